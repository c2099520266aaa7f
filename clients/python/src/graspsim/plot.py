"""Matplotlib helpers for tactile readings and work cycles (install the extra: pip install 'graspsim[plot]').

matplotlib is imported when a function here is called, never by `import graspsim`, so the client itself does
not need it. Figures made here are plain matplotlib Figures on the Agg canvas (no GUI, no pyplot state):

    import graspsim.plot
    result = client.run_work_cycle(scene_id, "cell", "cube", coverage=0.6)
    fig = graspsim.plot.work_cycle_figure({"60 %": result})
    graspsim.plot.save(fig, "cycle.png")

To draw into a window or a notebook instead, pass axes of your own (sums_over_time, tactile_image) or a
figure (work_cycle_figure(..., fig=plt.figure())).
"""
from __future__ import annotations

import os
from types import ModuleType
from typing import TYPE_CHECKING, Any, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike

from graspsim._sensors import TactileFrame
from graspsim._work_cycle import WorkCycleResult

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

MAX_INTENSITY = 4095  # 12-bit texels
CMAP = "inferno"      # the server's PNG heat maps use the same colour map (black = no pressure)


def _matplotlib() -> ModuleType:
    try:
        import matplotlib
    except ImportError as err:  # pragma: no cover - depends on the installation
        raise ImportError("graspsim.plot needs matplotlib: pip install 'graspsim[plot]' "
                          "(or 'clients/python[plot]' from the repository)") from err
    return matplotlib


def new_figure(figsize: Tuple[float, float] = (8.0, 5.0), dpi: float = 100) -> Figure:
    """A matplotlib Figure on the Agg canvas: drawable and savable without pyplot or a display."""
    _matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def save(fig: Figure, path: Union[str, os.PathLike[str]], dpi: Optional[float] = None) -> str:
    """Writes the figure (format from the suffix, e.g. .png) through the Agg canvas; returns the path."""
    _matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)  # a pyplot figure of an interactive backend: save it without that backend
    fig.savefig(os.fspath(path), dpi=dpi)
    return os.fspath(path)


def tactile_image(ax: Axes, frame_or_array: Union[TactileFrame, ArrayLike], max_intensity: float = MAX_INTENSITY,
                  *, colorbar: bool = False, title: Optional[str] = None, cmap: str = CMAP) -> Any:
    """Draws a pad's intensities (rows, cols) as a heat map: row 0 at the top (the server's PNG layout), one
    square per texel, 0 .. max_intensity on the colour map. Returns the AxesImage."""
    _matplotlib()
    if isinstance(frame_or_array, TactileFrame):
        values = frame_or_array.intensities
        if title is None:
            title = f"{frame_or_array.sensor_id}  t = {frame_or_array.time:.2f} s  sum {frame_or_array.intensity_sum}"
    else:
        values = np.asarray(frame_or_array)
    if values.ndim != 2:
        raise ValueError(f"tactile_image: need (rows, cols) intensities, got shape {values.shape}")
    image = ax.imshow(values, cmap=cmap, vmin=0, vmax=max_intensity, origin="upper", interpolation="nearest",
                      aspect="equal")
    ax.set_xlabel("col")
    ax.set_ylabel("row")
    if title:
        ax.set_title(title, fontsize="small")
    if colorbar:
        ax.figure.colorbar(image, ax=ax, label="intensity")
    return image


def _stage_boundaries(ax: Axes, result: WorkCycleResult, labels: bool = True, label: Optional[str] = None) -> None:
    """Dotted lines where each stage after the first starts; names at the top, stages closer than 2.5 % of the
    time range to the previous one joined to its label ("release, done")."""
    starts = result.stage_starts()[1:]
    span = float(result.time[-1] - result.time[0]) if len(result) > 1 else 1.0
    groups: List[List[Any]] = []
    for i, (name, start) in enumerate(starts):
        ax.axvline(start, color="0.6", linewidth=0.8, linestyle=":", zorder=0, label=label if i == 0 else None)
        if groups and start - groups[-1][0] < 0.025 * span:
            groups[-1][1].append(name)
        else:
            groups.append([start, [name]])
    if labels:
        for start, names in groups:
            ax.annotate(", ".join(names), xy=(start, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -3),
                        textcoords="offset points", rotation=90, va="top", ha="left", fontsize="x-small",
                        color="0.35")


def _headroom(ax: Axes, top: float) -> None:
    """Room above the curves for the stage names."""
    ax.set_ylim(0, max(ax.get_ylim()[1], 1.25 * top) if top > 0 else None)


def sums_over_time(ax: Axes, result: WorkCycleResult, *, label: str = "", color: Optional[str] = None,
                   setpoint: bool = True, stages: bool = True, legend: bool = True) -> List[Any]:
    """Both pads' intensity sums against time (left solid, right dashed), the set-point (dash-dotted) and the
    stage boundaries (dotted, named). Returns the two Line2D of the sums."""
    _matplotlib()
    prefix = f"{label} " if label else ""
    (left,) = ax.plot(result.time, result.left_sum, color=color, linewidth=1.4, label=f"{prefix}left pad")
    (right,) = ax.plot(result.time, result.right_sum, color=left.get_color(), linewidth=1.4, linestyle="--",
                       label=f"{prefix}right pad")
    if setpoint:
        ax.axhline(result.tactile_setpoint, color="k", linewidth=0.8, linestyle="-.",
                   label=f"set-point {result.tactile_setpoint:.0f}")
    if stages:
        _stage_boundaries(ax, result)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("tactile sum (intensity)")
    peak = max(float(result.left_sum.max(initial=0)), float(result.right_sum.max(initial=0)))
    _headroom(ax, max(peak, result.tactile_setpoint if setpoint else 0.0))
    ax.grid(True, alpha=0.3)
    if legend:
        ax.legend(fontsize="small", loc="center right")
    return [left, right]


def work_cycle_figure(results_by_label: Mapping[str, WorkCycleResult], *, title: Optional[str] = None,
                      fig: Optional[Figure] = None) -> Figure:
    """The figure of the paper's Fig. 7: the tactile sum against time for several runs (e.g. coverages), one
    colour per run with the left pad solid and the right dashed, the set-point, and the stage boundaries of the
    first run; below it, the object's height change (mm), which shows the lift and any slip. Returns the figure
    (a new one on the Agg canvas unless `fig` is given)."""
    _matplotlib()
    from matplotlib.lines import Line2D

    if not results_by_label:
        raise ValueError("work_cycle_figure: no results")
    fig = fig if fig is not None else new_figure(figsize=(9.0, 6.5))
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    handles = []
    peak = 0.0
    for i, (label, result) in enumerate(results_by_label.items()):
        color = f"C{i % 10}"
        sums_over_time(top, result, label=label, color=color, setpoint=False, stages=False, legend=False)
        handles.append(Line2D([], [], color=color, linewidth=1.4, label=label))
        peak = max(peak, float(result.left_sum.max(initial=0)), float(result.right_sum.max(initial=0)))
        if len(result):
            rise = (result.object_position[:, 2] - result.object_position[0, 2]) * 1e3
            bottom.plot(result.time, rise, color=color, linewidth=1.4, label=label)
    handles += [Line2D([], [], color="0.3", linewidth=1.4, label="left pad"),
                Line2D([], [], color="0.3", linewidth=1.4, linestyle="--", label="right pad")]
    setpoints = sorted({r.tactile_setpoint for r in results_by_label.values()})
    for value in setpoints:
        top.axhline(value, color="k", linewidth=0.8, linestyle="-.")
        handles.append(Line2D([], [], color="k", linewidth=0.8, linestyle="-.", label=f"set-point {value:.0f}"))
    first_label, first = next(iter(results_by_label.items()))
    if len(first):
        _stage_boundaries(top, first)
        _stage_boundaries(bottom, first, labels=False)
        handles.append(Line2D([], [], color="0.6", linewidth=0.8, linestyle=":",
                              label=f"stages of {first_label}" if len(results_by_label) > 1 else "stages"))
    _headroom(top, max([peak] + setpoints))
    top.set_xlabel("")
    top.legend(handles=handles, fontsize="small", loc="center right")
    top.set_title(title or "tactile sum during the work cycle")
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("object rise (mm)")
    bottom.grid(True, alpha=0.3)
    fig.align_ylabels([top, bottom])
    fig.tight_layout()
    return fig


def peak_images_figure(result: WorkCycleResult, *, index: Optional[int] = None, title: Optional[str] = None,
                       fig: Optional[Figure] = None) -> Figure:
    """Both pads' tactile images at one frame (default: where the summed intensity peaks), with a colour bar."""
    _matplotlib()
    if not len(result):
        raise ValueError("peak_images_figure: the result has no frames")
    i = result.peak_index() if index is None else int(index)
    fig = fig if fig is not None else new_figure(figsize=(5.0, 5.0))
    axes = fig.subplots(1, 2)
    for ax, name, images, sums in ((axes[0], result.left_id or "left", result.left_images, result.left_sum),
                                   (axes[1], result.right_id or "right", result.right_images, result.right_sum)):
        image = tactile_image(ax, images[i], title=f"{name}\nsum {sums[i]:.0f}")
    fig.colorbar(image, ax=list(axes), label="intensity", shrink=0.8)
    fig.suptitle(title or f"t = {result.time[i]:.2f} s ({result.stage[i]})", fontsize="medium")
    return fig


__all__: Sequence[str] = ["new_figure", "peak_images_figure", "save", "sums_over_time",
                          "tactile_image", "work_cycle_figure"]
