"""Plots of evaluation results (matplotlib, written as PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from hsgplan.files import atomic  # noqa: E402


def save_figure(fig, path: Path) -> None:
    """Write a figure whole or not at all (`hsgplan.files.atomic`) and free it."""
    try:
        with atomic(path) as tmp:
            fig.savefig(tmp)
    finally:
        plt.close(fig)


def plot_success_by_size(
    ours: dict[str, dict[int, tuple[float, float | None]]],
    paper: dict[str, dict[int, float]],
    path: Path,
) -> None:
    """Success rate by problem size, one colour per method: ours solid (with the standard
    deviation over repeats as error bars), the paper's dashed.

    Args:
        ours: method -> size -> (success rate, its standard deviation or None).
        paper: method -> size -> the paper's success rate.
        path: where the PNG goes.
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=120)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (method, by_size) in enumerate(ours.items()):
        colour = colours[k % len(colours)]
        sizes = sorted(by_size)
        rates = [by_size[n][0] for n in sizes]
        errors = [by_size[n][1] or 0.0 for n in sizes]
        ax.errorbar(sizes, rates, yerr=errors, color=colour, marker="o", capsize=3, label=method)
        if method in paper:
            ps = sorted(paper[method])
            ax.plot(
                ps,
                [paper[method][n] for n in ps],
                color=colour,
                linestyle="--",
                marker="x",
                alpha=0.7,
                label=f"{method} (paper)",
            )
    ax.set_xlabel("objects in the goal")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # no tick at 2.5 objects
    ax.set_ylabel("success rate")
    ax.set_ylim(0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    save_figure(fig, path)


def plot_times_by_size(series: dict[str, dict[str, dict[int, float]]], path: Path) -> None:
    """Seconds per episode by problem size on a log scale, task planning (left) and motion
    (right), one colour per solver.

    Args:
        series: solver -> level ("task" / "motion") -> size -> seconds.
        path: where the PNG goes.
    """
    fig, axes = plt.subplots(1, 2, figsize=(9.6, 4.0), dpi=120, sharey=True)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, level in zip(axes, ("task", "motion"), strict=True):
        for k, (solver, levels) in enumerate(series.items()):
            by_size = levels[level]
            sizes = sorted(by_size)
            dashed = "(paper)" in solver
            ax.plot(
                sizes,
                [max(by_size[n], 1e-5) for n in sizes],
                color=colours[k % len(colours)],
                linestyle="--" if dashed else "-",
                marker="x" if dashed else "o",
                label=solver,
            )
        ax.set_yscale("log")
        ax.set_xlabel("objects in the goal")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_title(f"{level} seconds per episode")
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("seconds (log scale)")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)


def plot_learning_curves(
    series: dict[str, dict[int, dict[int, float]]], paper: dict[int, float], path: Path
) -> None:
    """Success rate against the number of demonstrations (log scale), one panel per series and
    one colour per problem size; the paper's rate at each size as a dashed line.

    Args:
        series: series name -> demonstrations -> size -> success rate.
        paper: size -> the paper's success rate (drawn where the series have that size).
        path: where the PNG goes.
    """
    fig, axes = plt.subplots(
        1, len(series), figsize=(4.4 * len(series), 3.8), dpi=120, sharey=True, squeeze=False
    )
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (name, points) in zip(axes[0], series.items(), strict=True):
        counts = sorted(points)
        sizes = sorted({n for p in points.values() for n in p})
        for k, n in enumerate(sizes):
            colour = colours[k % len(colours)]
            xs = [c for c in counts if n in points[c]]
            ax.plot(xs, [points[c][n] for c in xs], color=colour, marker="o", label=f"{n} objects")
            if n in paper:
                ax.axhline(paper[n], color=colour, linestyle="--", alpha=0.6)
        ax.set_xscale("log", base=2)
        ax.set_xticks(counts, [str(c) for c in counts])
        ax.minorticks_off()
        ax.set_xlabel("demonstrations")
        ax.set_title(name, fontsize=9)
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("success rate (dashed: the paper's)")
    axes[0][-1].legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)
