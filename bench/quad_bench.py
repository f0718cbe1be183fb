#!/usr/bin/env python3
"""Runs `polycube quad` over a list of meshes and writes a markdown table of the results.

Usage: bench/quad_bench.py [--binary build/polycube] [--output bench/quad-table.md]
                           [--extra-args "..."] [MESH ...]

Default meshes: every mesh of ../shared/data/paper and ../shared/data/dev when present
(laurana-open with --fill-holes). Per mesh, from the --report JSON: quads, irregular vertices and
P's cone points, the refinement's rounds, halved chord parts and template rounds, angle deviation from 90° (mean / p95 / max), flipped quads / inverted corners / sharp corners (beyond 60° from square; before → after the
mending of the corners when it ran),
degenerate quads, the Hausdorff distance (% of the diagonal, both one-sided distances), the fit's
pulled corners, the triangles the map was built on (the model's long edges split: rounds), seconds
per stage, wall time and peak RSS (/usr/bin/time). Standard library only.
"""
import argparse
import os
import pathlib
import sys
import tempfile

from map_bench import ROOT, default_meshes, run_command


def run(binary, mesh, extra):
    # The report is read back and the directory removed with the quads.
    with tempfile.TemporaryDirectory(prefix="polycube-quad-bench-") as out:
        report_path = os.path.join(out, "report.json")
        return run_command([binary, "quad", mesh, "-o", os.path.join(out, "quads.obj"), "--report", report_path, "--quiet"] + extra,
                           mesh, report_path)


def mended(r, what):
    """The inverted or sharp corners, "before → after" the mending of the corners when it ran."""
    q, c = r["quality"], r.get("corners_mended")
    after = q.get(what + "_corners", "–")
    return "%d→%s" % (c[what + "_before"], after) if c else str(after)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=str(ROOT / "build" / "polycube"))
    ap.add_argument("--output", default=str(ROOT / "bench" / "quad-table.md"))
    ap.add_argument("--extra-args", default="")
    ap.add_argument("meshes", nargs="*")
    a = ap.parse_args()
    meshes = a.meshes or default_meshes()
    extra = a.extra_args.split() if a.extra_args else []
    stage_names = ("read", "split", "align", "topology", "polycube", "map", "grid", "carry", "smooth", "fit", "untangle", "refine", "quality", "retry")
    rows = []
    for mesh in meshes:
        name = pathlib.Path(mesh).stem
        code, r, wall, rss, error = run(a.binary, mesh, extra)
        if r is None:
            rows.append("| %s | failed (exit %d): %s |%s %.2f | %.0f |" % (name, code, error.replace("|", "/"), " |" * 12, wall, rss))
            print(name, "failed", error, file=sys.stderr)
            continue
        q, s = r["quality"], r["seconds"]
        ang = q["angle_deviation_degrees"]
        sides = q["hausdorff_sides"]
        diag = q["diagonal"]
        stages = " / ".join("%.2f" % s.get(k, 0) for k in stage_names)
        g = r.get("grid", {})
        split = r.get("split", {})
        rows.append("| %s | %d | %d / %d / %d | %d | %d | %.2f / %.1f / %.1f | %d / %s / %s | %d | %.3f (%.3f / %.3f) | %d | %s | %s | %.2f | %.2f | %.0f |" % (
            name, q["quads"], g.get("refine_rounds", 0), g.get("refined_chord_parts", 0), g.get("template_rounds", 0), q["irregular_vertices"], q["irregular_at_corners"], ang["mean"], ang["p95"], ang["max"],
            q["flipped_quads"], mended(r, "inverted"), mended(r, "sharp"), q["degenerate_quads"], q["hausdorff_percent_diagonal"],
            100 * sides["quads_to_model"] / diag, 100 * sides["model_to_quads"] / diag,
            r.get("fitting", {}).get("snapped", 0),
            "%d (%d)" % (split["triangles"], split["rounds"]) if split else "-", stages, s["total"], wall, rss))
        print(rows[-1], file=sys.stderr)
    header = [
        "| mesh | quads | refinement rounds / parts halved / template rounds | irregular | of them at P's cones | angle dev. mean / p95 / max ° | flipped / inverted corners / sharp corners | degenerate | Hausdorff % diag (quads→model / model→quads) | corners pulled by the fit | triangles mapped (split rounds) | seconds " + " / ".join(stage_names) + " | total s | wall s | peak RSS MB |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    with open(a.output, "w") as f:
        f.write("\n".join(header + rows) + "\n")
    print("wrote", a.output, file=sys.stderr)


if __name__ == "__main__":
    main()
