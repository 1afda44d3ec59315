"""Output stage: pictures of an operation, 3D with PyVista and 2D layers with matplotlib.

Both libraries load on first use.  3D pictures render off-screen through EGL
unless ``VTK_DEFAULT_OPENGL_WINDOW`` says otherwise, so they work on a machine
without a display.

Examples
--------
::

    op = gcodekit.gcode_to_operation("part.gcode")
    gcodekit.visualize.plot_operation(op, scalars="speed", screenshot="part.png")
    gcodekit.visualize.plot_layer(op, 10).figure.savefig("layer10.png")
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import NothingToShowError, check_choice

if TYPE_CHECKING:
    import pyvista as pv
    from matplotlib.axes import Axes

    from .additive.part import AdditivePart
    from .model.operation import Operation

CAMERAS = ("iso", "top", "front", "side")
#: Scalars with a meaning beyond a waypoint column, and the colour-bar title of each.
NAMED_SCALARS = {"feature": "feature", "speed": "speed (mm/s)", "layer": "layer", "time": "elapsed time (s)",
                 "feed": "feed (mm/min)", "tool": "tool", "laser": "heat source on"}
_TRAVEL_COLOR = "#9a9a9a"
#: matplotlib's "tab10", one colour per category (a colormap name would be sampled at its ends for two)
_CATEGORY_COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                    "#bcbd22", "#17becf"]
_MAX_GLYPHS = 300


def move_masks(op: "Operation") -> tuple[np.ndarray, np.ndarray]:
    """Waypoints that are the work and the rest of the moves.

    The work is the depositing moves from the first layer on (start-code purge
    lines are not the part) or, for a mill, the feed moves.
    """
    moving = op.moving.copy()
    moving[:1] = False  # a move is drawn from the waypoint before it
    work = op.work & moving
    return work, moving & ~work


def waypoint_scalars(op: "Operation", scalars: str) -> tuple[np.ndarray, list[str] | None]:
    """Values of ``scalars`` at every waypoint, and category names for a categorical one.

    ``feature`` (slicer ``;TYPE:`` or DED fraction comments), ``speed`` (each
    move's length over its planned time, mm/s), ``layer``, ``time`` (elapsed,
    s), or any waypoint column (``feed``, ``tool``, ``laser``, ``z`` ...).
    """
    w = op.waypoints
    if scalars == "feature":
        names, codes = np.unique(op.features.astype(str), return_inverse=True)
        return codes.astype(np.int32), [n or "(none)" for n in names.tolist()]
    if scalars == "speed":
        d, t = np.asarray(w["distance"], float), np.nan_to_num(np.asarray(w["time"], float))
        return np.divide(d, t, out=np.zeros_like(d), where=t > 0), None
    if scalars == "layer":
        return op.layers, None
    if scalars in ("time", "elapsed_time"):
        return op.elapsed_time(), None
    check_choice("scalars", scalars, [*NAMED_SCALARS, *sorted(k for k in w if k not in NAMED_SCALARS and k != "command")])
    return np.asarray(w[scalars]), None


def _lines(pv, w: dict, xyz: np.ndarray, rows: np.ndarray) -> "pv.PolyData":
    """One line cell per move (move ``i`` runs from waypoint ``i-1`` to ``i``).

    The cells share the waypoint points; an arc's cell passes through its
    interior points (every 5 degrees), added after them.
    """
    from .emulate.arcs import waypoint_arc_points

    interior, counts = waypoint_arc_points(w, rows)
    size = counts + 2
    # VTK's cell array: per cell its size, its start, its interior points, its end
    cells = np.empty(int((size + 1).sum()), np.int64)
    head = np.cumsum(size + 1) - (size + 1)
    cells[head] = size
    cells[head + 1] = rows - 1
    cells[head + size] = rows
    inside = np.ones(cells.size, bool)
    inside[np.r_[head, head + 1, head + size]] = False
    cells[inside] = xyz.shape[0] + np.arange(interior.shape[0])
    mesh = pv.PolyData(np.vstack([xyz, interior]) if interior.size else xyz, lines=cells)
    # the points no cell uses (the rest of the program) must not move the camera
    drawn = np.vstack([xyz[np.r_[rows - 1, rows]], interior])
    if drawn.size:
        mesh.field_data["drawn_bounds"] = np.r_[drawn.min(axis=0), drawn.max(axis=0)]
    return mesh


def operation_polydata(op: "Operation", scalars: str = "feature") -> tuple["pv.PolyData", "pv.PolyData", list | None]:
    """The work moves (with ``scalars`` as cell data) and the travel moves of ``op`` as line meshes."""
    from .export.vtk import import_pyvista

    pv = import_pyvista()
    w = op.waypoints
    xyz = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
    work, travel = move_masks(op)
    values, categories = waypoint_scalars(op, scalars)
    work_rows = np.flatnonzero(work)
    mesh = _lines(pv, w, xyz, work_rows)
    values = values[work_rows]
    if categories is not None:  # keep the categories the drawn moves have
        used, values = np.unique(values, return_inverse=True)
        categories = [categories[k] for k in used]
    mesh.cell_data[scalars] = values
    a, b = np.asarray(w["a"], float), np.asarray(w["b"], float)
    if np.any(a != 0) or np.any(b != 0):
        from .analysis import tool_vectors

        mesh.cell_data["tool_vector"] = tool_vectors(a[work_rows], b[work_rows])
    return mesh, _lines(pv, w, xyz, np.flatnonzero(travel)), categories


def _glyphs(pv, mesh: "pv.PolyData", size: float) -> "pv.PolyData":
    """Arrows along the tool direction at up to ``_MAX_GLYPHS`` moves."""
    centers = mesh.cell_centers()
    step = max(1, centers.n_points // _MAX_GLYPHS)
    picked = pv.PolyData(centers.points[::step])
    picked["tool_vector"] = mesh.cell_data["tool_vector"][::step]
    return picked.glyph(orient="tool_vector", scale=False, factor=size, geom=pv.Arrow())


def default_scalars(op: "Operation") -> str:
    """``feature`` when the program names its features, else ``layer`` (additive) or ``feed``."""
    if op.flavor is not None and op.flavor.feature_comment and (op.features != "").any():
        return "feature"
    return "layer" if op.process == "additive" else "feed"


def plot_operation(op: "Operation", scalars: str | None = None, *, show_travel: bool = False,
                   tool_vectors: bool = False, off_screen: bool = True, screenshot: str | os.PathLike | None = None,
                   camera: str = "iso", window_size: tuple[int, int] = (1200, 900), line_width: float = 2.0,
                   cmap: str | None = None, background: str = "white",
                   scalar_bar: bool = True) -> np.ndarray | None:
    """Draw the toolpath of an emulated operation in 3D with PyVista.

    Parameters
    ----------
    op : Operation
    scalars : str, default: None
        Colour by ``feature``, ``speed``, ``layer``, ``time`` or any waypoint
        column (see :func:`waypoint_scalars`); None picks ``feature`` when
        the program marks features, else ``layer`` (additive) or ``feed``.
    show_travel : bool, default: False
        Also draw the moves that lay no material (rapids for a mill), grey.
    tool_vectors : bool, default: False
        Arrows along the head direction (5-axis DED programs).
    off_screen : bool, default: True
        Render without a window; False opens an interactive one.
    screenshot : path, default: None
        Write a PNG of the picture there.
    camera : {"iso", "top", "front", "side"}, default: "iso"
    scalar_bar : bool, default: True
        Draw the colour bar (the legend of a categorical scalar).

    Returns
    -------
    The image as an (height, width, 3) array when off-screen, else None.
    """
    check_choice("camera", camera, CAMERAS)
    if not _is_emulated(op):
        raise ValueError(f"{op.file}: plot_operation needs an emulated operation (use gcode_to_operation)")
    from .export.vtk import import_pyvista

    pv = import_pyvista()
    scalars = scalars or default_scalars(op)
    mesh, travel, categories = operation_polydata(op, scalars)
    if mesh.n_cells == 0 and (travel.n_cells == 0 or not show_travel):
        raise NothingToShowError(f"{op.file}: nothing to draw (no {'deposition' if op.process == 'additive' else 'feed'} "
                                 "moves)")
    plotter = pv.Plotter(off_screen=off_screen, window_size=list(window_size))
    plotter.set_background(background)
    bar: dict[str, Any] = dict(title=NAMED_SCALARS.get(scalars, scalars), color="black", vertical=True,
                               position_x=0.88, position_y=0.1, height=0.8, width=0.04,
                               title_font_size=18, label_font_size=14,
                               fmt="%.0f" if mesh[scalars].dtype.kind in "iu" else "%.4g")
    kwargs: dict[str, Any] = dict(scalars=scalars, line_width=line_width, scalar_bar_args=bar,
                                  show_scalar_bar=scalar_bar,
                                  cmap=cmap or "viridis")
    if categories:
        if cmap is None:
            kwargs["cmap"] = _CATEGORY_COLORS[:len(categories)] if len(categories) <= 10 else "tab20"
        kwargs.update(categories=True, clim=[-0.5, len(categories) - 0.5],
                      annotations={k: name for k, name in enumerate(categories)})
        bar.update(n_labels=0, n_colors=len(categories))
    if mesh.n_cells:
        plotter.add_mesh(mesh, **kwargs)
    if show_travel and travel.n_cells:
        plotter.add_mesh(travel, color=_TRAVEL_COLOR, line_width=max(line_width / 2, 1.0), opacity=0.6)
    if tool_vectors and "tool_vector" in mesh.cell_data:
        lo_hi = mesh.field_data["drawn_bounds"]
        size = 0.04 * float(np.linalg.norm(lo_hi[3:] - lo_hi[:3]))
        plotter.add_mesh(_glyphs(pv, mesh, size), color="#d62728")
    {"iso": plotter.view_isometric, "top": plotter.view_xy, "front": plotter.view_xz,
     "side": plotter.view_yz}[camera]()
    _frame(plotter, mesh if mesh.n_cells else travel)
    if not off_screen:
        plotter.show()
        return None
    image = plotter.screenshot(None if screenshot is None else str(screenshot), return_img=True)
    plotter.close()
    return image


def _is_emulated(op) -> bool:
    return getattr(op, "waypoints", None) is not None


def _frame(plotter, mesh) -> None:
    """Fit the camera to the drawn moves only (not the machine's home position)."""
    lo, hi = mesh.field_data["drawn_bounds"][:3], mesh.field_data["drawn_bounds"][3:]
    plotter.reset_camera(bounds=[lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]])
    plotter.camera.zoom(1.05)


def plot_layer(source: "Operation | AdditivePart", layer: int, *, ax: "Axes | None" = None,
               scalars: str = "feature", show_travel: bool = True, line_width: float = 1.2) -> "Axes":
    """Draw one layer from above with matplotlib: its work moves coloured by ``scalars``, travel dashed.

    Parameters
    ----------
    source : Operation or AdditivePart
    layer : int
        0-based, as ``Operation.layers`` numbers them.
    ax : matplotlib Axes, default: a new figure's

    Returns
    -------
    The Axes drawn on.
    """
    from matplotlib.collections import LineCollection

    op = getattr(source, "operation", source)
    if not _is_emulated(op):
        raise ValueError(f"{op.file}: plot_layer needs an emulated operation (use gcode_to_operation)")
    in_layer = (source.waypoint_layer if hasattr(source, "waypoint_layer") else op.layers) == layer
    work, travel = move_masks(op)
    if not (work & in_layer).any():
        raise NothingToShowError(f"{op.file}: layer {layer} has no deposition moves")
    if ax is None:
        import matplotlib.pyplot as plt

        ax = plt.subplots(figsize=(7, 6))[1]
    w = op.waypoints
    xy = np.column_stack([np.asarray(w["x"], float), np.asarray(w["y"], float)])

    def segments(mask):
        rows = np.flatnonzero(mask)
        return np.stack([xy[rows - 1], xy[rows]], axis=1), rows

    values, categories = waypoint_scalars(op, scalars)
    segs, rows = segments(work & in_layer)
    lines = LineCollection(segs, linewidths=line_width, cmap="tab10" if categories else "viridis")
    lines.set_array(values[rows].astype(float))
    if categories:
        lines.set_clim(-0.5, 9.5)
    ax.add_collection(lines)
    if show_travel:
        tsegs, _ = segments(travel & in_layer)
        ax.add_collection(LineCollection(tsegs, linewidths=0.5, colors=_TRAVEL_COLOR, linestyles="dashed"))
    if categories:
        import matplotlib.lines as mlines

        used = np.unique(values[rows])
        handles = [mlines.Line2D([], [], color=lines.cmap(lines.norm(k)), label=categories[k]) for k in used]
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    else:
        ax.figure.colorbar(lines, ax=ax, label=NAMED_SCALARS.get(scalars, scalars))
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("X (mm)")
    ax.set_ylabel("Y (mm)")
    ax.set_title(f"{os.path.basename(op.file)}: layer {layer}")
    return ax
