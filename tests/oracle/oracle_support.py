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


def parse_msh22(path):
    """Physical names, nodes by tag and elements (type, physical, nodes) of an ASCII MSH 2.2 file."""
    lines = open(path).read().split("\n")
    names, nodes, elems = {}, {}, []
    i = 0
    while i < len(lines):
        s = lines[i].strip()
        if s == "$PhysicalNames":
            for k in range(int(lines[i + 1])):
                d, t, n = lines[i + 2 + k].split(maxsplit=2)
                names[(int(d), int(t))] = n.strip('"')
        elif s == "$Nodes":
            for k in range(int(lines[i + 1])):
                f = lines[i + 2 + k].split()
                nodes[int(f[0])] = [float(x) for x in f[1:4]]
        elif s == "$Elements":
            for k in range(int(lines[i + 1])):
                f = [int(x) for x in lines[i + 2 + k].split()]
                ntags = f[2]
                elems.append((f[1], f[3], f[3 + ntags:]))
        i += 1
    return names, nodes, elems
