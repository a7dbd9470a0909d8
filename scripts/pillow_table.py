#!/usr/bin/python3
"""Regenerates the "pillow + smooth" table of docs/pillowing.md.

For each case: extraction (`isohex mesh`), boundary pillowing (`isohex pillow`), untangling and
shape optimisation with the boundary fixed (`isohex smooth --untangle`), then `isohex quality`
and `isohex sheets` on every stage. Prints the Markdown table and the commands it ran.

    /usr/bin/python3 scripts/pillow_table.py [--isohex build-pillow/bin/isohex]
                                             [--work /tmp/pillow-table] [--reuse] [--only NAME ...]

--reuse skips a stage whose output and timing file already exist (the timing is read back), so
an interrupted run can be resumed. Timings are wall-clock seconds of each command.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import time

DATA = "/work/shared/data"
V = DATA + "/volumes"

# name -> (volume preparation commands or None, `isohex mesh` arguments)
CASES = [
    ("headsq", None, [V + "/headsq_64x64x93_int16le.raw", "--dims", "64", "64", "93", "--type", "i16",
                      "--spacing", "3.2", "3.2", "1.5", "--iso", "1150", "--cell-size", "3.2"]),
    ("bucky", None, [V + "/bucky_32x32x32_uint8.raw", "--dims", "32", "32", "32", "--type", "u8",
                     "--iso", "51", "--cell-size", "1"]),
    ("ironProt", None, [V + "/ironProt.vtk", "--iso", "128", "--cell-size", "1"]),
    ("MR head", None, [V + "/HeadMRVolume.mhd", "--iso", "40", "--cell-size", "4"]),
    ("cthead", None, [V + "/cthead_256x256x113_int16be.raw", "--dims", "256", "256", "113", "--type", "i16",
                      "--endian", "big", "--spacing", "1", "1", "2", "--iso", "600", "--cell-size", "4"]),
    ("mAChE", ["volume", "molecule", DATA + "/molecules/mache_1MAH.pqr", "-o", "{work}/mache.vti"],
     ["{work}/mache.vti", "--iso", "1", "--cell-size", "1"]),
]


def run(cmd, timing_file, output, reuse, ok=(0,)):
    """Runs cmd (a list) unless --reuse and its output exists; returns the wall time. `ok`:
    accepted exit codes (`smooth --untangle` exits 1 when inverted hexes remain)."""
    if reuse and os.path.exists(output) and os.path.exists(timing_file):
        with open(timing_file) as f:
            return float(f.read())
    print("$ " + " ".join(shlex.quote(c) for c in cmd), file=sys.stderr, flush=True)
    t = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    elapsed = time.monotonic() - t
    if p.returncode not in ok:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
    with open(timing_file, "w") as f:
        f.write(f"{elapsed:.3f}\n")
    return elapsed


def quality(isohex, mesh, json_file, reuse):
    run([isohex, "quality", mesh, "--json", json_file], json_file + ".time", json_file, reuse)
    with open(json_file) as f:
        q = json.load(f)
    sj = q["metrics"]["scaled_jacobian"]
    # "inverted" counts SJ < 0, "questionable" 0 <= SJ < 0.2; degenerate hexes (zero volume,
    # reported as 1e30) are counted as inverted here.
    bad = sj["inverted"] + sj["degenerate"]
    return {"hexes": q["hexes"], "min": sj["min"], "neg": bad, "lt02": bad + sj["questionable"]}


FACES = ((0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2), (0, 3, 2, 1), (4, 5, 6, 7))


def folded(pts, quad):
    """A quad is folded (or degenerate) if its corner normals do not all agree with its mean
    normal: no hex on it can then have positive scaled Jacobians at all four corners."""
    p = [pts[i] for i in quad]
    normals = []
    for k in range(4):
        a, b, c = p[k], p[(k + 1) % 4], p[(k + 3) % 4]
        u = [b[i] - a[i] for i in range(3)]
        w = [c[i] - a[i] for i in range(3)]
        normals.append((u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]))
    n = [sum(x[i] for x in normals) for i in range(3)]
    return min(sum(x[i] * n[i] for i in range(3)) for x in normals) <= 0


def why_inverted(isohex, mesh, reuse):
    """Of the hexes with SJ < 0 (or degenerate) in `mesh`: how many have a boundary face, and
    how many a folded boundary face. The boundary is fixed through pillow and smooth, so a
    hex on a folded boundary quad cannot be made positive by moving interior vertices."""
    import vtk  # Debian's python3-vtk
    csv = mesh + ".sj.csv"
    run([isohex, "quality", mesh, "--per-element", csv], csv + ".time", csv, reuse)
    bad = set()
    with open(csv) as f:
        for line in f:
            i, v = line.strip().split(",")
            if i.isdigit() and (float(v) < 0 or float(v) > 1):  # > 1: degenerate (1e30)
                bad.add(int(i))
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(mesh)
    r.Update()
    g = r.GetOutput()
    pts = [g.GetPoint(i) for i in range(g.GetNumberOfPoints())]
    hexes = [[g.GetCell(c).GetPointId(k) for k in range(8)] for c in range(g.GetNumberOfCells())]
    count = {}
    for h in hexes:
        for f in FACES:
            key = tuple(sorted(h[k] for k in f))
            count[key] = count.get(key, 0) + 1
    on_boundary = on_folded = near_folded = 0
    folded_quads = [[h[k] for k in f] for h in hexes for f in FACES
                    if count[tuple(sorted(h[k] for k in f))] == 1 and folded(pts, [h[k] for k in f])]
    folded_vertices = {v for q in folded_quads for v in q}
    for c in bad:
        faces = [[hexes[c][k] for k in f] for f in FACES]
        boundary = [q for q in faces if count[tuple(sorted(q))] == 1]
        on_boundary += bool(boundary)
        on_folded += any(folded(pts, q) for q in boundary)
        near_folded += any(v in folded_vertices for v in hexes[c])
    return {"bad": len(bad), "on_boundary": on_boundary, "on_folded": on_folded, "near_folded": near_folded,
            "folded_quads": len(folded_quads)}


def sheets(isohex, mesh, json_file, reuse):
    run([isohex, "sheets", mesh, "--json", json_file], json_file + ".time", json_file, reuse)
    with open(json_file) as f:
        return json.load(f)


def prepared_cases(a):
    """The cases --only selects, each with its work folder (made), the {work} formatter and its
    `isohex mesh` arguments, after running its volume preparation."""
    for name, prep, mesh_args in CASES:
        if a.only and name not in a.only:
            continue
        work = os.path.join(a.work, name.replace(" ", "_"))
        os.makedirs(work, exist_ok=True)
        f = lambda s, work=work: s.format(work=work)
        if prep:
            out = f(prep[prep.index("-o") + 1])
            run([a.isohex] + [f(x) for x in prep], out + ".time", out, a.reuse)
        yield name, work, f, mesh_args


def pipeline(a):
    """`isohex mesh` with its defaults on every case: its own stage table, what the band released,
    and the sheets after pillowing (from its report)."""
    print("| case | extraction: hexes, min SJ, SJ < 0, SJ < 0.2 | final: hexes, min SJ, SJ < 0, SJ < 0.2 | "
          "boundary captured by one sheet, hexes with ≥ 2 boundary faces | released vertices (max distance) | "
          "parts dropped | time |")
    print("|---|---|---|---|---|--:|--:|")
    for name, work, f, mesh_args in prepared_cases(a):
        P = os.path.join(work, "pipeline.vtu")
        t = run([a.isohex, "mesh"] + [f(x) for x in mesh_args] + ["-o", P, "--json", P + ".json"], P + ".time", P,
                a.reuse, ok=(0, 1))
        s = sheets(a.isohex, P, P + ".sheets.json", a.reuse)
        with open(P + ".json") as fh:
            j = json.load(fh)
        st = {r["stage"]: r for r in j["stages"]}

        def cell(r):
            sj = r["scaled_jacobian"]
            return f"{r['hexes']:,}, {sj['min']:.3f}, {sj['inverted'] + sj['degenerate']:,}, {r['below_0.2']:,}"

        one = all(len(c["sheets"]) == 1 for c in s["boundary_components"])
        multi = s["multi_boundary_hexes"]
        rel = j["released_vertices"] + (j["optimisation"]["boundary"]["loose"] - j["released_vertices"])
        far = j["released_max_distance"] / j["cell_size"]
        print(f"| {name} | {cell(st['extraction'])} | {cell(st['optimisation'])} | "
              f"{'yes' if one else 'no'} ({len(s['boundary_components'])} components), {multi} | "
              f"{rel:,} ({far:.2f} cells) | {j['dropped_components']:,} | {t:.1f} s |")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--isohex", default="build-pillow/bin/isohex")
    ap.add_argument("--work", default="/tmp/pillow-table")
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--without-pillow", nargs="*", default=[],
                    help="cases to also smooth straight from the extraction, for comparison")
    ap.add_argument("--pipeline", action="store_true",
                    help="instead: one `isohex mesh` per case with its defaults (pillowing, then sliding "
                         "optimisation with the band release) and the table of its stages")
    a = ap.parse_args()
    if a.pipeline:
        return pipeline(a)
    rows, direct = [], []
    # Newer `isohex mesh` runs pillowing and smoothing itself unless told not to: the first
    # stage here is extraction + surface smoothing only.
    help_text = subprocess.run([a.isohex, "mesh", "--help"], stdout=subprocess.PIPE, text=True).stdout
    stage_flags = [flag for flag in ("--no-pillow", "--no-smooth") if flag in help_text]
    for name, work, f, mesh_args in prepared_cases(a):
        A, B, C = (os.path.join(work, x) for x in ("a.vtu", "b.vtu", "c.vtu"))
        t_mesh = run([a.isohex, "mesh"] + [f(x) for x in mesh_args] + stage_flags + ["-o", A, "--json", A + ".json"],
                     A + ".time", A, a.reuse)
        t_pillow = run([a.isohex, "pillow", A, "-o", B, "--json", B + ".json"], B + ".time", B, a.reuse)
        t_smooth = run([a.isohex, "smooth", B, "-o", C, "--untangle", "--json", C + ".json"], C + ".time", C,
                       a.reuse, ok=(0, 1))
        qa, qb, qc = (quality(a.isohex, m, m + ".quality.json", a.reuse) for m in (A, B, C))
        sa, sb = (sheets(a.isohex, m, m + ".sheets.json", a.reuse) for m in (A, B))
        with open(B + ".json") as fh:
            p = json.load(fh)
        rows.append((name, qa, qb, qc, t_mesh, t_pillow, t_smooth, p, sa, sb, why_inverted(a.isohex, C, a.reuse)))
        if name in a.without_pillow:
            D = os.path.join(work, "a_smooth.vtu")
            t = run([a.isohex, "smooth", A, "-o", D, "--untangle", "--json", D + ".json"], D + ".time", D, a.reuse,
                    ok=(0, 1))
            direct.append((name, qa, quality(a.isohex, D, D + ".quality.json", a.reuse), qc, t))

    def stage(q):
        return f"{q['hexes']:,} | {q['min']:.3f} | {q['neg']:,} | {q['lt02']:,}"

    print("| case | stage | hexes | min SJ | SJ < 0 | SJ < 0.2 | time |")
    print("|---|---|--:|--:|--:|--:|--:|")
    for name, qa, qb, qc, tm, tp, ts, p, sa, sb, w in rows:
        print(f"| {name} | extraction | {stage(qa)} | {tm:.1f} s |")
        print(f"| | + pillow | {stage(qb)} | {tp:.1f} s |")
        print(f"| | + smooth | {stage(qc)} | {ts:.1f} s |")
    print()
    print("| case | boundary components | capturing sheets per component before → after | "
          "hexes with ≥ 2 boundary faces before → after | inverted new hexes | folded vertices |")
    print("|---|--:|---|---|--:|--:|")
    for name, qa, qb, qc, tm, tp, ts, p, sa, sb, w in rows:
        def capture(s):
            counts = [len(c["sheets"]) for c in s["boundary_components"]]
            return f"{min(counts)}–{max(counts)}" if min(counts) != max(counts) else f"{counts[0]}"
        print(f"| {name} | {len(sb['boundary_components'])} | {capture(sa)} → {capture(sb)} | "
              f"{p['multi_boundary_hexes_before']:,} → {p['multi_boundary_hexes_after']:,} | "
              f"{p.get('inverted_new_hexes', 'n/a')} | {p.get('folded_vertices', 'n/a')} |")

    print()
    print("| case | folded boundary quads | SJ < 0 after smooth | ... with a boundary face | "
          "... with a folded boundary face | ... with a vertex of one | smooth's infeasibility proofs |")
    print("|---|--:|--:|--:|--:|--:|--:|")
    for name, qa, qb, qc, tm, tp, ts, p, sa, sb, w in rows:
        with open(os.path.join(os.path.dirname(p["output"]), "c.vtu.json")) as fh:
            proofs = json.load(fh)["untangle"]["infeasible"]
        kinds = {}
        for x in proofs:
            kinds[x["kind"]] = kinds.get(x["kind"], 0) + 1
        print(f"| {name} | {w['folded_quads']:,} | {w['bad']:,} | {w['on_boundary']:,} | {w['on_folded']:,} | "
              f"{w['near_folded']:,} | {', '.join(f'{n} {k}' for k, n in sorted(kinds.items())) or '0'} |")

    if direct:
        print()
        print("| case | extraction: SJ < 0 / < 0.2 | smooth alone | pillow + smooth |")
        print("|---|--:|--:|--:|")
        for name, qa, qd, qc, t in direct:
            print(f"| {name} | {qa['neg']:,} / {qa['lt02']:,} | {qd['neg']:,} / {qd['lt02']:,} ({t:.1f} s) | "
                  f"{qc['neg']:,} / {qc['lt02']:,} |")


if __name__ == "__main__":
    main()

