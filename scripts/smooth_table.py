#!/usr/bin/python3
"""`isohex smooth` on the shared third-party hex meshes (ECR 2015 inputs, Mesquite's test
meshes), measured as a solver sees them (issue 15): per mesh and boundary setting, hexes not
certified valid inside and with det J <= 0 at a Gauss point, the smallest jacobian ratio (with
the count below 0.1), the largest edge ratio, below 0.2 / inverted by the scaled Jacobian, and
the hexes the untangler proves cannot all be valid with the fixed vertices (`untangle.infeasible`)
and the sets of hexes the worst pass proves cannot all reach 0.2 (`worst.proven`, with the bound),
and how many hexes below 0.2 are in none of those sets.

    /usr/bin/python3 scripts/smooth_table.py --cli build/bin/isohex --data ../shared/data [--only NAME,...]

Prints a Markdown table (docs/optimization.md has the last one).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paper_table import inside_measures  # noqa: E402

# name, file (under hexmeshes/), extra `isohex smooth` options per setting
SETTINGS = [("fixed", []), ("slide + band 0.3", ["--boundary", "slide", "--surface-band", "0.3"])]


def meshes(data):
    h = os.path.join(data, "hexmeshes")
    out = [(f"ECR {n}_in", os.path.join(h, f"ecr2015_{n}_in.mesh")) for n in ("block", "bust", "dragon", "armadillo")]
    out += [(f"Mesquite {n}", os.path.join(h, "mesquite", f"{n}.vtk"))
            for n in ("hex_5_tangled", "pave1.e", "pave2.e", "pave3.e", "pave_cyl.e")]
    return [(n, p) for n, p in out if os.path.exists(p)]


def below_in_no_proof(cli, mesh, tmp, proofs):
    """Hexes of `mesh` below a scaled Jacobian of 0.2 that are in none of the proofs' sets: where
    the optimiser falls short of what the fixed vertices are proven to allow, or the proofs do."""
    csv = os.path.join(tmp, "sj.csv")
    subprocess.run([cli, "quality", mesh, "--per-element", csv], check=True, capture_output=True)
    explained = {h for p in proofs for h in p["hexes"]}
    n = 0
    with open(csv) as f:
        for line in f:
            if line[:1].isdigit():
                h, v = line.split(",")
                n += float(v) < 0.2 and int(h) not in explained
    return n


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default="build/bin/isohex")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))
    ap.add_argument("--only", default="", help="comma-separated mesh name prefixes")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="isohex-smooth-")
    print("| mesh | setting | hexes | not valid inside / det J ≤ 0 at a Gauss point | min jacobian ratio (< 0.1) | "
          "max edge ratio | below 0.2 / inverted | min SJ | proven impossible | below 0.2 in no proof | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, path in meshes(args.data):
        if args.only and not any(name.startswith(o) for o in args.only.split(",")):
            continue
        for label, extra in SETTINGS:
            out, rep = os.path.join(tmp, "out.vtu"), os.path.join(tmp, "smooth.json")
            t = time.monotonic()
            run = subprocess.run([args.cli, "smooth", path, "-o", out, "--untangle", "--json", rep] + extra,
                                 capture_output=True, text=True)
            wall = time.monotonic() - t
            if not os.path.exists(rep):
                print(f"| {name} | {label} | failed ({run.returncode}): {run.stderr.strip()[-200:]} |||||||")
                continue
            r = json.load(open(rep))
            m = inside_measures(args.cli, out, tmp)
            q = r["after"]
            proofs = r.get("untangle", {}).get("infeasible", [])
            # Sets of hexes that cannot all reach 0.2 with the fixed vertices (worst.proven), where
            # some are left below it (with the band, the proofs of the first pass, with the feature
            # vertices pinned, no longer hold).
            if q["below_0.2"]:
                proofs += [dict(p, kind=f"{p['kind']} ≤ {p['bound']:.4f}") for p in r.get("worst", {}).get("proven", [])]
            unproven = below_in_no_proof(args.cli, out, tmp, proofs) if q["below_0.2"] else 0
            impossible = ", ".join(f"{p['kind']} {p['hexes']}" for p in proofs[:3]) + (" …" if len(proofs) > 3 else "")
            print(f"| {name} | {label} | {r['hexes']:,} | {m['invalid']:,} / {m['gauss']:,} | {m['ratio']:.3f} "
                  f"({m['poor']:,}) | {m['edge_ratio']:.1f} | {q['below_0.2']:,} / {q['inverted']:,} | {q['min']:.3f} | "
                  f"{len(proofs)}{': ' + impossible if proofs else ''} | {unproven:,} | {wall:.1f} |", flush=True)
            os.remove(rep)


if __name__ == "__main__":
    main()
