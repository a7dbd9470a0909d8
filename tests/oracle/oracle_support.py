"""What the oracle tests share besides VTK (vtk_support.py): their command line, a fresh work
folder, and the tally of failed checks with the exit code it gives."""
import argparse
import os
import shutil

FAILURES = []


def check(ok, what):
    """Counts a failed check (and prints it); returns ok."""
    if not ok:
        FAILURES.append(what)
        print("FAIL:", what)
    return ok


def oracle_args(description, extra=None):
    """--cli, --data, --tmp (emptied and made), and what `extra(parser)` adds."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    if extra:
        extra(ap)
    args = ap.parse_args()
    shutil.rmtree(args.tmp, ignore_errors=True)
    os.makedirs(args.tmp)
    return args


def finish():
    """The exit code: 1 if any check failed."""
    if FAILURES:
        print(f"{len(FAILURES)} failures")
        return 1
    print("all checks passed")
    return 0
