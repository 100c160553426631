#!/usr/bin/python3
"""Error-versus-time plot of the SDF bench (tetrasand_bench_sdf --csv): GPU scan conversion and
OpenVDB meshToLevelSet, each point one mesh at one resolution, error against the CPU exact SDF;
the exact path itself (error 0 by definition) is drawn on the bottom edge at its time.
Usage: /usr/bin/python3 bench/plot_sdf.py sdf.csv out.png  (Debian's python3-matplotlib)"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, png_path):
    rows = list(csv.DictReader(open(csv_path)))
    floor = 1e-8  # where exact (error 0) and errors below it are drawn on the log axis
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharex=True)
    for ax, stat in zip(axes, ("mean", "max")):
        for path, colour, marker in (("gpu", "tab:blue", "o"), ("openvdb", "tab:orange", "s")):
            t = [float(r[path + "_s" if path == "gpu" else "openvdb_s"]) for r in rows]
            e = [max(float(r[f"{path}_{stat}"]), floor) for r in rows]
            ax.scatter(t, e, c=colour, marker=marker,
                       label="tetrasand GPU (llvmpipe)" if path == "gpu" else "OpenVDB meshToLevelSet")
            for r, x, y in zip(rows, t, e):
                ax.annotate(f"{r['mesh']}@{r['resolution']}", (x, y), fontsize=6, xytext=(3, 3),
                            textcoords="offset points")
        t = [float(r["exact_s"]) for r in rows]
        ax.scatter(t, [floor] * len(t), c="tab:green", marker="^", label="CPU exact (reference, error 0)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{stat} |d - exact| [voxels]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, loc="center left")
    fig.suptitle("SDF construction: error against exact distance versus time")
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
