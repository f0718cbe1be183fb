#!/usr/bin/env python3
"""Runs `polycube map` over a list of meshes and writes a markdown table of the results.

Usage: bench/map_bench.py [--binary build/polycube] [--output bench/map.md] [--paper-parameters]
                          [--extra-args "..."] [MESH ...]

Default meshes: every mesh of ../shared/data/paper and ../shared/data/dev when present
(laurana-open with --fill-holes). With --paper-parameters, meshes listed in
../shared/reference/paper-table1.csv run with the paper's d_z and d_a; the others with the
defaults. Per mesh: triangles, genus, d_z, d_a, corners, ε_angle, ε_area, flipped image triangles
both ways (the independent audit), seconds per stage, wall time and peak RSS (/usr/bin/time), and
the paper's figures beside ours. Standard library only.
"""
import argparse
import csv
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared"


def paper_table():
    path = SHARED / "reference" / "paper-table1.csv"
    rows = {}
    if path.exists():
        with open(path) as f:
            for row in csv.DictReader(f):
                rows[row["model"].lower()] = row
    return rows


def default_meshes():
    meshes = []
    for folder in ("paper", "dev"):
        d = SHARED / "data" / folder
        if d.is_dir():
            meshes += sorted(str(p) for p in d.iterdir() if p.suffix in (".obj", ".off", ".ply", ".stl"))
    return meshes


def run_command(command, mesh, report_path):
    """Runs a polycube command under /usr/bin/time (the laurana-open mesh closed by --fill-holes).
    Returns (exit code, the report read from report_path or None, wall s, peak RSS MB, error)."""
    args = ["/usr/bin/time", "-f", "%e %M"] + command
    if "laurana-open" in mesh:
        args.append("--fill-holes")
    start = time.time()
    proc = subprocess.run(args, capture_output=True, text=True)
    wall = time.time() - start
    lines = proc.stderr.strip().splitlines()
    rss_mb = float(lines[-1].split()[1]) / 1024 if lines and len(lines[-1].split()) == 2 else float("nan")
    report = None
    if proc.returncode == 0:
        with open(report_path) as f:
            report = json.load(f)
    # The one-line error; /usr/bin/time's own lines come after it.
    errors = [l for l in lines if l.startswith("polycube: error:")]
    error = "" if proc.returncode == 0 else (errors[-1] if errors else "exit %d" % proc.returncode)
    return proc.returncode, report, wall, rss_mb, error


def run(binary, mesh, extra):
    # The files are read back into the report and removed with their directory.
    with tempfile.TemporaryDirectory(prefix="polycube-bench-") as out:
        return run_command([binary, "map", mesh, "-o", out, "--quiet"] + extra, mesh, os.path.join(out, "report.json"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=str(ROOT / "build" / "polycube"))
    ap.add_argument("--output", default=str(ROOT / "bench" / "map.md"))
    ap.add_argument("--paper-parameters", action="store_true")
    ap.add_argument("--extra-args", default="")
    ap.add_argument("meshes", nargs="*")
    a = ap.parse_args()
    meshes = a.meshes or default_meshes()
    paper = paper_table()
    rows = []
    for mesh in meshes:
        name = pathlib.Path(mesh).stem
        key = name.split("-")[0].lower()
        extra = a.extra_args.split() if a.extra_args else []
        dz = da = None
        if a.paper_parameters and key in paper and paper[key]["dz"]:
            dz, da = paper[key]["dz"], paper[key]["da"]
            extra += ["--dz", dz, "--da", da]
        code, r, wall, rss, error = run(a.binary, mesh, extra)
        p = paper.get(key)
        paper_cols = "%s / %s / %s min" % (p["eps_angle"], p["eps_area"], p["minutes"]) if p else ""
        if r is None:
            rows.append("| %s | | | | | | | | | | | %.2f | %.0f | failed (exit %d): %s | %s |" % (name, wall, rss, code, error.replace("|", "/"), paper_cols))
            print(name, "failed", error, file=sys.stderr)
            continue
        m = r.get("map", {})
        s = r["seconds"]
        # smooth: the smoothing of the P kept plus, when the refinement changed P, that of the
        # unrefined P it was compared with.
        smooth = s.get("smooth", 0) + s.get("smooth_unrefined", 0)
        # retry: the other orientation candidates finished because the first map fell short.
        stages = " / ".join("%.2f" % x for x in (s.get("align", 0), s.get("topology", 0), s.get("polycube", 0), s.get("map", 0),
                                                  s.get("refine", 0), smooth, s.get("untangle", 0), s.get("retry", 0)))
        # The last untangling of the files (image_untangle.h): images moved, largest shift.
        u = m.get("untangling") or {}
        moved = sum(u.get(d, {}).get("moved", 0) for d in ("polycube_to_model", "model_to_polycube"))
        shift = max([u.get(d, {}).get("max_shift", 0) for d in ("polycube_to_model", "model_to_polycube")])
        untangled = "%d, %.2f %%" % (moved, 100 * shift) if moved else "–"
        pm, mp = m.get("polycube_to_model", {}), m.get("model_to_polycube", {})
        # Degenerate image triangles (area <= 1e-14 of the target's) are counted apart by the audit.
        flips = "%d / %d" % (pm.get("flipped", -1), mp.get("flipped", -1))
        if pm.get("degenerate", 0) or mp.get("degenerate", 0):
            flips += " (+ %d / %d degenerate)" % (pm.get("degenerate", 0), mp.get("degenerate", 0))
        result = "ok" if len(r.get("alignment", {}).get("finished", [])) < 2 else "ok, %d finished" % len(r["alignment"]["finished"])
        # The exact sampling (map_overlay.h), tried when the finished map missed the contract.
        exact = m.get("exact") or {}
        if "kept" in exact:
            result += ", exact sampling %s (%.2f s)" % ("kept" if exact["kept"] else "tried", exact.get("seconds_total", 0))
        elif "error" in exact:
            result += ", exact sampling failed"
        rows.append("| %s | %d | %d | %s | %s | %d | %.3f | %.3f | %s | %.4f | %s | %s | %.2f | %.0f | %s | %s |" % (
            name, r["input"]["faces"], r["input"]["genus"], r["parameters"]["dz"], r["parameters"]["da"],
            r["polycube"]["corners"], m.get("eps_angle", float("nan")), m.get("eps_area", float("nan")),
            flips, pm.get("area_ratio", float("nan")), untangled, stages, s["total"], rss,
            result, paper_cols))
        print(rows[-1], file=sys.stderr)
    header = [
        "| mesh | triangles | genus | d_z | d_a | corners | ε_angle | ε_area | flipped P→M / M→P | image area / model area | images moved, largest shift (% of diagonal) | seconds align / topology / polycube / map / refine / smooth / untangle / retry | total s | peak RSS MB | result | paper ε_angle / ε_area / time |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    with open(a.output, "w") as f:
        f.write("\n".join(header + rows) + "\n")
    print("wrote", a.output, file=sys.stderr)


if __name__ == "__main__":
    main()
