#!/usr/bin/env python3
"""A picture of what `repose rig` made: a coronal slice of G beside the same slice of the body-part
map S, with every joint of skeleton.json marked and named (projected onto the slice).

usage: plot-rig.py G.nii.gz RIG_DIR OUT.png
"""
import json
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import nibabel as nib  # noqa: E402
import numpy as np  # noqa: E402


def main():
    g_path, rig, out = sys.argv[1:4]
    G = nib.as_closest_canonical(nib.load(g_path))
    S = nib.as_closest_canonical(nib.load(f"{rig}/S.nii.gz"))
    g, s = np.asarray(G.dataobj), np.asarray(S.dataobj)
    skeleton = json.load(open(f"{rig}/skeleton.json"))
    # The coronal slice through the joints' mean depth (RAS y).
    centres = np.array([j["ras"] for j in skeleton["joints"]])
    inv = np.linalg.inv(G.affine)
    j_ijk = (inv @ np.c_[centres, np.ones(len(centres))].T)[:3].T
    y = int(round(np.median(j_ijk[:, 1])))
    sx, sz = abs(G.affine[0, 0]), abs(G.affine[2, 2])
    fig, axes = plt.subplots(1, 2, figsize=(12, 12 * g.shape[2] * sz / (2 * g.shape[0] * sx) + 1))
    for ax, data, cmap, title in ((axes[0], g[:, y, :], "tab20b", "G (organs)"),
                                  (axes[1], s[:, y, :], "tab20", "S (body parts) and joints")):
        shown = np.ma.masked_equal(data.T, 0)
        # Canonical RAS+: i grows towards the patient's right, drawn to the right (a view from
        # behind the patient).
        ax.imshow(shown, origin="lower", cmap=cmap, interpolation="nearest",
                  aspect=sz / sx)
        ax.set_title(title)
        ax.set_xticks([])
        ax.set_yticks([])
    for j, (i, _, k) in zip(skeleton["joints"], j_ijk):
        axes[1].plot(i, k, "o", ms=7, mfc="white", mec="black")
        axes[1].annotate(j["name"], (i, k), xytext=(4, 4), textcoords="offset points", fontsize=7)
        flex = np.array(j["axes"].get("flexion", [0, 0, 0]))
        a = (inv[:3, :3] @ flex) * 6
        axes[1].plot([i - a[0], i + a[0]], [k - a[2], k + a[2]], "k-", lw=1)
    fig.suptitle(f"repose rig: {skeleton.get('convention', '')}, {len(skeleton['joints'])} joints")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print(out)


if __name__ == "__main__":
    main()
