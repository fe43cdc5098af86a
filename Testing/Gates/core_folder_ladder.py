"""Gate: Core's folders form a ladder (issue 55). A folder includes only folders below it, and
only through their public headers (issue 66).

The ladder, lowest first, is LADDER below and the picture in docs/ARCHITECTURE.md. Every
`#include` in Core/src and Core/include/repose that names a Core folder ("repose/pose/...",
"util/...", "../raster/...") is checked: a folder may include itself and the folders below it,
never one above. A folder's private headers (Core/src/FOLDER/*.h, included as "FOLDER/X.h" or
"../FOLDER/X.h") are its own: another folder includes what it shares from Core/include/repose.
A folder of Core that the ladder does not list fails too, so a new folder is placed on purpose.
Before it reads the tree the gate checks itself on a tree it makes, with one include that climbs
and one that reaches into another folder's private header, so it cannot pass by finding
nothing.

    core_folder_ladder.py SOURCE_DIR
"""
import pathlib
import re
import sys
import tempfile

# Lowest first. util and numerics know nothing of medical images; volume is the image; cage and
# io read and hold them; skeleton is the joints' conventions and file; mesh, raster the method's
# steps; rig reads a user's body; dosimetry the tissues and the FDTD model (its files included);
# pose runs the job; phantom, the generated bodies, may use everything.
LADDER = ["util", "numerics", "volume", "cage", "io", "skeleton", "mesh", "raster", "rig",
          "dosimetry", "pose", "phantom"]

INCLUDE = re.compile(r'^\s*#\s*include\s*["<](?:repose/|\.\./)?(\w+)/')
# An include of a header in Core/src rather than Core/include/repose: "mesh/X.h", "../mesh/X.h".
PRIVATE = re.compile(r'^\s*#\s*include\s*"(?!repose/)(?:\.\./)?(\w+)/')


def violations(core):
    """Each include that climbs, as 'file:line: folder includes higher'; and unplaced folders."""
    rank = {name: i for i, name in enumerate(LADDER)}
    found = []
    roots = [core / "src", core / "include" / "repose"]
    folders = {p.name for root in roots if root.is_dir() for p in root.iterdir() if p.is_dir()}
    for name in sorted(folders - set(rank)):
        found.append(f"Core folder '{name}' is not on the ladder (Testing/Gates/core_folder_ladder.py)")
    for root in roots:
        for path in sorted(root.rglob("*")):
            if not path.is_file() or path.suffix not in (".h", ".cpp", ".in", ".hpp"):
                continue
            own = path.relative_to(root).parts[0]
            if own not in rank:
                continue
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                m = INCLUDE.match(line)
                if not m or m.group(1) not in rank or m.group(1) == own:
                    continue
                if rank[m.group(1)] > rank[own]:
                    found.append(f"{path.relative_to(core.parent)}:{number}: {own} includes "
                                 f"{m.group(1)}, which stands above it")
                elif PRIVATE.match(line):
                    found.append(f"{path.relative_to(core.parent)}:{number}: {own} includes a "
                                 f"private header of {m.group(1)} (share it from "
                                 f"Core/include/repose/{m.group(1)})")
    return found


def self_check():
    with tempfile.TemporaryDirectory() as tmp:
        core = pathlib.Path(tmp) / "Core"
        (core / "src" / "util").mkdir(parents=True)
        (core / "src" / "pose").mkdir(parents=True)
        (core / "src" / "util" / "Low.cpp").write_text('#include "repose/pose/High.h"\n')
        (core / "src" / "pose" / "High.cpp").write_text('#include "repose/util/Low.h"\n')
        found = violations(core)
        if len(found) != 1 or "util includes pose" not in found[0]:
            sys.exit(f"gate self-check: expected one climbing include, found {found}")
        (core / "src" / "pose" / "Reach.cpp").write_text('#include "../util/Private.h"\n')
        found = violations(core)
        if len(found) != 2 or not any("private header of util" in v for v in found):
            sys.exit(f"gate self-check: a private header reached from another folder, found {found}")
        (core / "src" / "pose" / "Reach.cpp").unlink()
        (core / "src" / "newfolder").mkdir()
        if not any("'newfolder' is not on the ladder" in v for v in violations(core)):
            sys.exit("gate self-check: an unplaced folder was not reported")


def main():
    self_check()
    core = pathlib.Path(sys.argv[1]) / "Core"
    if not (core / "src").is_dir():
        sys.exit(f"{core / 'src'}: not a folder")
    found = violations(core)
    for v in found:
        print(v)
    if found:
        sys.exit(f"{len(found)} include(s) break Core's ladder or reach a private header: " +
                 " < ".join(LADDER))
    print("Core's folders form a ladder, each sharing only public headers: " +
          " < ".join(LADDER))


if __name__ == "__main__":
    main()
