"""Rewrites the docs' tables of numbers from what docs/regenerate.sh made.

    python3 docs/doc_tables.py STATS_DIR

- docs/renderer.md "Error against cost (rendering)": docs/render_quality/render_quality.csv
  (its rows of 8, 16, 32, 48, 64, 96, 128 and 256 steps; the default, 48, bold);
- docs/physics.md "Error against run time (physics)": docs/convergence/convergence.csv (its
  rows of dt 0.1, 0.5, 1, 2, 5, 10, 60 and 600 s; the default, 5 s, bold);
- the cloud-field statistics tables of README.md and docs/physics.md: the
  `cumulus stats` output saved as STATS_DIR/NAME for fair_weather and bomex.

Only the rows of those tables change; the text around them is left alone
(say in it what changed). tests/docs_numbers.rs checks the result.
"""

import csv
import math
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def sig(v, digits=2):
    """`v` with `digits` significant figures, plain decimal (0 for 0)."""
    if v == 0:
        return "0"
    decimals = max(0, digits - 1 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{decimals}f}"


def replace_table(text, marker, rows):
    """Replaces the body rows of the first table after `marker`."""
    start = text.index(marker)
    lines = text[start:].split("\n")
    i = next(k for k, l in enumerate(lines) if l.startswith("|"))
    j = i
    while j < len(lines) and lines[j].startswith("|"):
        j += 1
    body = ["| " + " | ".join(r) + " |" for r in rows]
    lines[i + 2 : j] = body
    return text[:start] + "\n".join(lines)


def bold(cells):
    return [f"**{c}**" for c in cells]


def render_quality_rows():
    rows = list(csv.DictReader(open(ROOT / "docs/render_quality/render_quality.csv")))
    out = []
    for r in rows:
        steps = int(r["steps"])
        if steps not in (8, 16, 32, 48, 64, 96, 128, 256):
            continue
        cells = [
            str(steps),
            f"{float(r['wall_s']):.2f}",
            f"{float(r['mean_abs_error']):.4f}",
            f"{float(r['max_abs_error']):.2f}",
        ]
        out.append(bold(cells) if steps == 48 else cells)
    return out


def convergence_rows():
    rows = list(csv.DictReader(open(ROOT / "docs/convergence/convergence.csv")))
    out = []
    cols = [
        "err_z_m",
        "err_w_mps",
        "err_theta_v_K",
        "err_qc_gkg",
        "err_cloud_base_m",
        "err_cloud_top_m",
    ]
    for r in rows:
        dt = float(r["dt_s"])
        if dt not in (0.1, 0.5, 1, 2, 5, 10, 60, 600):
            continue
        life = float(r["life_mismatch"])
        cells = [r["dt_s"], sig(float(r["wall_s"]))]
        cells += [sig(float(r[c]), 3 if float(r[c]) >= 10 else 2) for c in cols]
        cells.append("0" if life == 0 else f"{life:.4f}")
        out.append(bold(cells) if dt == 5 else cells)
    return out


def stats_rows(stats_dir):
    out = []
    for name in ("fair_weather", "bomex"):
        # The full-precision values of stats.json: rounding the printed
        # ones again rounded 0.29151 (printed 0.2915) to 0.291.
        stats = json.loads((Path(stats_dir) / name / "stats.json").read_text())
        out.append(
            [
                f"`{name}.toml`",
                f"{stats['cloud_fraction']:.3f}",
                f"{stats['dimension']:.2f}",
                f"{stats['size_fit']['slope']:.2f} ({stats['size_decades']:.1f})",
            ]
        )
    return out


def rewrite(name, tables):
    """Replaces the tables of ROOT/name, (marker, rows) each, atomically."""
    path = ROOT / name
    text = path.read_text()
    for marker, rows in tables:
        text = replace_table(text, marker, rows)
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text(text)
    tmp.replace(path)
    print(f"{name}: tables rewritten")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: python3 docs/doc_tables.py STATS_DIR")
    stats = stats_rows(sys.argv[1])
    rewrite("docs/renderer.md", [("### Error against cost (rendering)", render_quality_rows())])
    rewrite(
        "docs/physics.md",
        [("## Error against run time (physics)", convergence_rows()), ("Today's fields (", stats)],
    )
    rewrite("README.md", [("The field statistics of the shipped scenes", stats)])


if __name__ == "__main__":
    main()
