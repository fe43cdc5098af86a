"""Gate: the Logic's classes keep small public faces (issue 55).

Each class header Logic/vtkSlicerRepose*Logic.h (the module's logic and its parts) declares at
most MAX public member functions, as a Slicer module's logic does (CropVolume's has about 11):
state belongs in MRML nodes and rules in Core, so a growing face says something is in the wrong
layer. Counted: the distinct function names declared between `public:` and the next access
specifier, besides New and PrintSelf. Before it reads the tree the gate checks itself.

    logic_public_faces.py SOURCE_DIR
"""
import pathlib
import re
import sys

MAX = 25
DECL = re.compile(r"^\s+(?:static\s+|virtual\s+)?[\w:<>,\s\*&]*?[\s\*&](\w+)\s*\(")
ACCESS = re.compile(r"^\s*(public|protected|private)\s*:")
IGNORED = {"New", "PrintSelf", "vtkTypeMacro"}


def public_methods(text):
    names, public = set(), False
    for line in text.splitlines():
        m = ACCESS.match(line)
        if m:
            public = m.group(1) == "public"
            continue
        if not public or line.lstrip().startswith("//"):
            continue
        d = DECL.match(line)
        if d and d.group(1) not in IGNORED and not line.lstrip().startswith("return"):
            names.add(d.group(1))
    return names


def self_check():
    text = """class X : public vtkObject {
 public:
  static X* New();
  bool A(int a);
  const std::string& B() const { return b; }
  std::vector<int> C(const std::string& c,
                     int d);
  struct S {
    int value = 0;
  };
 protected:
  void D();
};"""
    got = public_methods(text)
    if got != {"A", "B", "C"}:
        sys.exit(f"gate self-check: expected A, B, C, got {sorted(got)}")


def main():
    self_check()
    root = pathlib.Path(sys.argv[1])
    failed = False
    for header in sorted((root / "Logic").glob("vtkSlicerRepose*Logic.h")):
        names = public_methods(header.read_text())
        print(f"{header.name}: {len(names)} public methods")
        if len(names) > MAX:
            print(f"  more than {MAX}: {', '.join(sorted(names))}")
            failed = True
    if failed:
        sys.exit("a Logic class's public face is larger than the house allows")


if __name__ == "__main__":
    main()
