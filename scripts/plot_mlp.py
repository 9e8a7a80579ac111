#!/usr/bin/python3
"""PNG plots of one MLP run directory (Debian's numpy and matplotlib).

    /usr/bin/python3 scripts/plot_mlp.py OUTPUT_DIR

Reads OUTPUT_DIR/summary.json and the CSV tables of the scene and writes, each
atomically:
- mlp_ordering: structure_factor.png, log10 S(q) over the wave-vector grid
  (the Fourier transform of the two-point density correlation, paper Fig. 2);
- mlp_compression: delta_h.png, the normalised widths against time (paper Fig. 5),
  and density_histograms.png (paper Fig. 3 b, d, f);
- mlp_beams: profiles.png, mean |F_return| across the contact (paper Fig. 6).
"""
import json
import os
import sys

from plotting import plt, save  # noqa: E402  (scripts/plotting.py)
import numpy as np  # noqa: E402


def table(directory, name):
    data = np.genfromtxt(os.path.join(directory, name + ".csv"), delimiter=",", names=True)
    return np.atleast_1d(data)


def ordering(d):
    s = table(d, "structure_factor")
    n = int(round(np.sqrt(len(s))))
    img = np.log10(np.maximum(s["S"].reshape(n, n), 1e-3))
    fig, ax = plt.subplots(figsize=(5, 4.5))
    ext = [s["qx"].min(), s["qx"].max(), s["qy"].min(), s["qy"].max()]
    im = ax.imshow(img, origin="lower", extent=ext, cmap="gray_r")
    fig.colorbar(im, ax=ax, label="log10 S(q)")
    ax.set_xlabel("q_x (1/m)")
    ax.set_ylabel("q_y (1/m)")
    ax.set_title("Structure factor")
    save(fig, os.path.join(d, "structure_factor.png"))


def compression(d):
    st = table(d, "statistics")
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(st["time"], st["delta_h"], label="delta_h (along the load)")
    ax.plot(st["time"], st["delta_w"], label="delta_w (transverse)")
    ax.set_xlabel("t (s)")
    ax.legend()
    save(fig, os.path.join(d, "delta_h.png"))
    path = os.path.join(d, "density_histograms.csv")
    if os.path.exists(path):
        h = table(d, "density_histograms")
        fig, ax = plt.subplots(figsize=(6, 3.5))
        for k in np.unique(h["snapshot"]):
            m = h["snapshot"] == k
            ax.plot(h["relative_density"][m], h["fraction"][m], label="t = %.3g s" % h["time"][m][0])
        ax.set_xlabel("relative density")
        ax.set_ylabel("fraction of particles")
        ax.legend()
        save(fig, os.path.join(d, "density_histograms.png"))


def beams(d):
    p = table(d, "profiles")
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(p["x_from_contact"], p["f_return_bond"], label="bond mean |F_return|")
    ax.plot(p["x_from_contact"], p["f_return_net"], label="net |F_return| (eq. 24)")
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("x - x_contact (m)")
    ax.set_ylabel("N/m")
    ax.legend()
    save(fig, os.path.join(d, "profiles.png"))


def main():
    d = sys.argv[1]
    with open(os.path.join(d, "summary.json")) as f:
        scene = json.load(f)["scene"]
    {"mlp_ordering": ordering, "mlp_compression": compression, "mlp_beams": beams}[scene](d)


if __name__ == "__main__":
    main()
