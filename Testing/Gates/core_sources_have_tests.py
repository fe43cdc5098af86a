"""Gate: every Core source file has its test (issue 55).

A file Core/src/<folder>/<Name>.cpp is covered by a test file of the same name,
<Name>Test.cpp anywhere under Testing/ (as libigl pairs headers and tests; one under
Testing/Cxx/Core must be in the same folder, Testing/Cxx/Core/<folder>/, as Core's tests mirror
Core's folders), or by a row of the
table "Tests of Core's sources" in docs/ARCHITECTURE.md that names it as `<folder>/<Name>.cpp`
and names the test files that cover it, each of which must exist. A new source file with
neither fails the gate, and so does a row naming a test file that is not there. Before it reads
the tree the gate checks itself on a tree it makes.

    core_sources_have_tests.py SOURCE_DIR
"""
import pathlib
import re
import sys
import tempfile

HEADING = "### Tests of Core's sources"
ROW = re.compile(r"^\|\s*`([\w/]+\.cpp)`\s*\|(.*)$")
TEST_PATH = re.compile(r"`(Testing/[\w./-]+)`")


def table(architecture):
    """{source: [test paths]} from the table's rows under HEADING (until the next heading)."""
    rows, inside = {}, False
    for line in architecture.read_text().splitlines():
        if line.startswith("#"):
            inside = line.strip() == HEADING
            continue
        m = ROW.match(line) if inside else None
        if m:
            rows[m.group(1)] = TEST_PATH.findall(m.group(2))
    return rows


def problems(root):
    tests = {p.stem for p in (root / "Testing").rglob("*Test.cpp")}
    tests |= {p.stem for p in (root / "Testing").rglob("*Test.cxx")}
    rows = table(root / "docs" / "ARCHITECTURE.md")
    core_tests = {p.stem: p for p in (root / "Testing" / "Cxx" / "Core").rglob("*Test.cpp")}
    found = []
    for source in sorted((root / "Core" / "src").rglob("*.cpp")):
        key = source.relative_to(root / "Core" / "src").as_posix()
        if source.stem + "Test" in tests:
            mirror = (root / "Testing" / "Cxx" / "Core" / source.parent.relative_to(root / "Core" / "src")
                      / (source.stem + "Test.cpp"))
            at = core_tests.get(source.stem + "Test")
            if at is not None and at != mirror:
                found.append(f"{at.relative_to(root).as_posix()}: tests Core/src/{key}, so it belongs in "
                             f"{mirror.relative_to(root).as_posix()}")
            continue
        if key not in rows:
            found.append(f"Core/src/{key}: no {source.stem}Test.cpp and no row in docs/ARCHITECTURE.md's "
                         f"\"{HEADING[4:]}\"")
        elif not rows[key]:
            found.append(f"docs/ARCHITECTURE.md: the row of {key} names no test file")
        for test in rows.get(key, []):
            if not (root / test).exists():
                found.append(f"docs/ARCHITECTURE.md: the row of {key} names {test}, which is not there")
    return found


def self_check():
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        for d in ("Core/src/io", "Testing/Cxx/Core/io", "docs"):
            (root / d).mkdir(parents=True)
        for f in ("Core/src/io/A.cpp", "Core/src/io/B.cpp", "Core/src/io/C.cpp",
                  "Testing/Cxx/Core/io/ATest.cpp", "Testing/Cxx/Core/OtherTest.cpp"):
            (root / f).write_text("")
        (root / "docs/ARCHITECTURE.md").write_text(
            f"{HEADING}\n\n| source | tests |\n|---|---|\n"
            "| `io/B.cpp` | `Testing/Cxx/Core/OtherTest.cpp` |\n## next\n")
        found = problems(root)
        if len(found) != 1 or "io/C.cpp" not in found[0]:
            sys.exit(f"gate self-check: expected io/C.cpp alone uncovered, found {found}")
        (root / "docs/ARCHITECTURE.md").write_text(
            f"{HEADING}\n| `io/B.cpp` | `Testing/Cxx/Core/GoneTest.cpp` |\n"
            "| `io/C.cpp` | `Testing/Cxx/Core/OtherTest.cpp` |\n")
        found = problems(root)
        if len(found) != 1 or "GoneTest.cpp, which is not there" not in found[0]:
            sys.exit(f"gate self-check: a missing test file was not reported: {found}")
        # A same-named test outside its source's folder.
        (root / "Testing/Cxx/Core/io/ATest.cpp").rename(root / "Testing/Cxx/Core/ATest.cpp")
        found = problems(root)
        if len(found) != 2 or not any("belongs in Testing/Cxx/Core/io/ATest.cpp" in f for f in found):
            sys.exit(f"gate self-check: a test outside its source's folder was not reported: {found}")


def main():
    self_check()
    root = pathlib.Path(sys.argv[1])
    found = problems(root)
    for p in found:
        print(p)
    if found:
        sys.exit(f"{len(found)} Core source file(s) without a test that says so")
    print("every Core source file has a same-named test or a row saying which test covers it")


if __name__ == "__main__":
    main()
