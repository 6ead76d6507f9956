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
    ours: dict[str, dict[int, tuple[float, tuple[float, float] | None]]],
    paper: dict[str, dict[int, float]],
    path: Path,
) -> None:
    """Success rate by problem size, one colour per method: ours solid (with its interval as
    error bars), the paper's dashed.

    Args:
        ours: method -> size -> (success rate, its interval (low, high) or None).
        paper: method -> size -> the paper's success rate.
        path: where the PNG goes.
        intervals: series -> amount -> column -> the success rate's 95% interval, drawn as a
            band where a point has one.
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=120)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (method, by_size) in enumerate(ours.items()):
        colour = colours[k % len(colours)]
        sizes = sorted(by_size)
        rates = [by_size[n][0] for n in sizes]
        spans = [by_size[n][1] or (by_size[n][0], by_size[n][0]) for n in sizes]
        errors = [
            [r - lo for r, (lo, _) in zip(rates, spans, strict=True)],
            [hi - r for r, (_, hi) in zip(rates, spans, strict=True)],
        ]
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
    shown = [n for by_size in ours.values() for n in by_size]
    if shown:  # half an object either side: one size alone is not stretched across the axis
        ax.set_xlim(min(shown) - 0.5, max(shown) + 0.5)
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
    series: dict[str, dict[int, dict[str, float]]],
    paper: dict[str, float],
    unit: str,
    path: Path,
    intervals: dict[str, dict[int, dict[str, tuple[float, float]]]] | None = None,
) -> None:
    """Success rate against how much data (log scale), one panel per series and one colour per
    column (a problem size, or a model); the paper's rate of a column as a dashed line.

    Args:
        series: series name -> amount of data -> column -> success rate.
        paper: column -> the paper's success rate (drawn where a series has that column).
        unit: what the amounts count (the x axis' label).
        path: where the PNG goes.
    """
    fig, axes = plt.subplots(
        1, len(series), figsize=(4.4 * len(series), 3.8), dpi=120, sharey=True, squeeze=False
    )
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (name, points) in zip(axes[0], series.items(), strict=True):
        amounts = sorted(points)
        columns = list(dict.fromkeys(col for a in amounts for col in points[a]))
        for k, col in enumerate(columns):
            colour = colours[k % len(colours)]
            xs = [a for a in amounts if col in points[a]]
            ax.plot(xs, [points[a][col] for a in xs], color=colour, marker="o", label=col)
            spread = (intervals or {}).get(name, {})
            banded = [a for a in xs if col in spread.get(a, {})]
            if banded:
                low, high = zip(*(spread[a][col] for a in banded), strict=True)
                ax.fill_between(banded, low, high, color=colour, alpha=0.15, linewidth=0)
            if col in paper:
                ax.axhline(paper[col], color=colour, linestyle="--", alpha=0.6)
        ax.set_xscale("log", base=2)
        ax.set_xticks(amounts, [f"{a:,}" for a in amounts])
        ax.minorticks_off()
        ax.set_xlabel(unit)
        ax.set_title(name, fontsize=9)
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("success rate" + (" (dashed: the paper's)" if paper else ""))
    axes[0][-1].legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)
