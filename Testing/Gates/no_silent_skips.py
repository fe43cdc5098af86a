"""Gate: no test skips itself because something is missing (issue 55).

scripts/install-deps.sh installs every dependency the tests use, and the shared data sits beside
the checkout, so a missing one is an error a test must report, not a smaller suite that passes.
Forbidden in Testing/: `pytest.importorskip`, `pytest.skip(`, and GoogleTest's `GTEST_SKIP` or
pytest's `skipif` unless the same line names the one documented condition, the sanitizer build
(`kAddressSanitizer`, `REPOSE_SANITIZE`, `UNDER_SANITIZER`: docs/RELIABILITY.md), under which a few child processes
cannot run. Before it reads the tree the gate checks itself on lines it makes.

    no_silent_skips.py SOURCE_DIR
"""
import pathlib
import re
import sys

FORBIDDEN = re.compile(r"importorskip|pytest\.skip\(|unittest\.skip|GTEST_SKIP|skipif|skipTest")
SANITIZER = re.compile(r"sanitiz", re.IGNORECASE)


def offending(line):
    return bool(FORBIDDEN.search(line)) and not SANITIZER.search(line)


def self_check():
    bad = ['pytest.importorskip("h5py")', 'if (!ok) GTEST_SKIP() << "no mpirun";',
           'pytest.skip("no data")', 'm = pytest.mark.skipif(True, reason="x")']
    good = ['if (kAddressSanitizer) GTEST_SKIP() << "mpirun under AddressSanitizer";',
            'needs = pytest.mark.skipif(os.environ.get("REPOSE_SANITIZE") == "1",']
    if not all(offending(b) for b in bad) or any(offending(g) for g in good):
        sys.exit("gate self-check: the rule misjudges its own examples")


def main():
    self_check()
    testing = pathlib.Path(sys.argv[1]) / "Testing"
    me = pathlib.Path(__file__).resolve()
    found = []
    for path in sorted(testing.rglob("*")):
        if path.suffix not in (".py", ".cpp", ".cxx", ".h") or path.resolve() == me:
            continue
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if offending(line):
                found.append(f"{path.relative_to(testing.parent)}:{number}: {line.strip()}")
    for f in found:
        print(f)
    if found:
        sys.exit(f"{len(found)} test(s) skip themselves: install what they need in "
                 "scripts/install-deps.sh and let its absence fail")
    print("no test skips itself for a missing dependency")


if __name__ == "__main__":
    main()
