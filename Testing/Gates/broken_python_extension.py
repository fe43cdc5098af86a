"""Gate: a broken Python extension fails the Python suite instead of skipping it (issue 26).

Copies the built `repose` package, renames its compiled extension, and has pytest collect the
suite against the copy: collection must fail, naming the extension. The intact copy must collect
cleanly, so the failure is the extension's and not the harness's. Collecting only (no test runs)
keeps this gate to seconds.

    broken_python_extension.py BUILD_PYTHON_DIR TESTS_DIR
"""
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile


def collect(python_path, tests):
    env = dict(os.environ, PYTHONPATH=str(python_path))
    return subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
         "--ignore", str(tests / "test_openems_sar.py"), str(tests)],
        env=env, capture_output=True, text=True)


def main():
    built, tests = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    extensions = list((built / "repose").glob("_repose*.so"))
    if len(extensions) != 1:
        sys.exit(f"gate: expected one compiled extension in {built / 'repose'}, found {extensions}")
    with tempfile.TemporaryDirectory() as tmp:
        copy = pathlib.Path(tmp) / "python"
        shutil.copytree(built, copy)
        intact = collect(copy, tests)
        if intact.returncode != 0:
            sys.exit(f"gate: the intact extension does not collect:\n{intact.stdout}{intact.stderr}")
        renamed = copy / "repose" / extensions[0].name
        renamed.rename(renamed.with_name("_renamed_by_gate.so"))
        broken = collect(copy, tests)
        output = broken.stdout + broken.stderr
        if broken.returncode == 0:
            sys.exit(f"gate: with the extension renamed the suite still collects:\n{output}")
        if "_repose" not in output:
            sys.exit(f"gate: the suite failed, but not on the missing extension:\n{output}")
    print("gate: the intact extension collects; a renamed one fails the suite")


if __name__ == "__main__":
    main()
