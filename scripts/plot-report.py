#!/usr/bin/python3
"""Plots of a `repose pose` report: per-label volume change (bars) and the distribution of
per-tet conformal distortion (histogram), as PNG beside the report.

    /usr/bin/python3 scripts/plot-report.py DIR/report.json [more reports...]
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402


def plot(report_path):
    with open(report_path) as f:
        r = json.load(f)
    out = os.path.dirname(os.path.abspath(report_path))
    title = f"{r['pose']} / {r['frame']}"

    labels = [l for l in r["labels"] if l["voxels_before"] >= 1000]
    names = [l["name"] or str(l["value"]) for l in labels]
    change = [l["change_percent"] for l in labels]
    fig, ax = plt.subplots(figsize=(10, 4.5))
    colours = ["tab:red" if abs(c) > 1 else "tab:blue" for c in change]
    ax.bar(range(len(change)), change, color=colours)
    ax.axhline(1, color="grey", linestyle="--", linewidth=0.8)
    ax.axhline(-1, color="grey", linestyle="--", linewidth=0.8)
    ax.set_xticks(range(len(change)))
    ax.set_xticklabels(names, rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("volume change (%)")
    body = r["body"]["volume_change_percent"]
    ax.set_title(f"{title}: per-label volume change (labels >= 1000 voxels; body {body:+.2f} %)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "volume_change.png"), dpi=100)
    plt.close(fig)

    bins = r["distortion"]["histogram"]
    fig, ax = plt.subplots(figsize=(7, 4))
    ticks = [f"{b['from']}–{b['to']}" for b in bins]
    ax.bar(range(len(bins)), [b["tets"] for b in bins], color="tab:green")
    ax.set_yscale("log")
    ax.set_xticks(range(len(bins)))
    ax.set_xticklabels(ticks, rotation=30, fontsize=8)
    ax.set_xlabel("singular value ratio of B_t (1: conformal)")
    ax.set_ylabel("tets")
    ax.set_title(f"{title}: per-tet distortion ({r['mesh']['inverted_tets']} inverted)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "distortion.png"), dpi=100)
    plt.close(fig)
    return [os.path.join(out, "volume_change.png"), os.path.join(out, "distortion.png")]


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        for png in plot(path):
            print(png)
