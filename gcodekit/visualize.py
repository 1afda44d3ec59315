"""Output stage: pictures of an operation, 3D with PyVista and 2D projections with matplotlib.

Both draw the one :class:`~gcodekit.view.Toolpath` (segments, arcs in
chords) coloured by the one :class:`~gcodekit.view.Coloring`, seen by the
orthographic :class:`~gcodekit.view.Camera` the notebook viewer uses, so a
PNG, a report figure and the viewer show a program alike.  Both libraries
load on first use.  3D pictures render off-screen through EGL unless
``VTK_DEFAULT_OPENGL_WINDOW`` says otherwise, so they work on a machine
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

from .errors import NothingToShowError
from .view import TRAVEL, TRAVEL_COLOR, WORK, Camera, Coloring, Toolpath, coloring, default_coloring

if TYPE_CHECKING:
    import pyvista as pv
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .additive.part import AdditivePart
    from .model.operation import Operation

_MAX_GLYPHS = 300


def toolpath_polydata(path: Toolpath, color: Coloring) -> tuple["pv.PolyData", "pv.PolyData"]:
    """The work segments (``color``'s values as cell data named ``color.by``) and the travel segments as meshes.

    Each segment is a line cell of two points; for 5-axis programs the work
    mesh also carries each segment's ``tool_vector``.
    """
    from .export.vtk import import_pyvista

    pv = import_pyvista()
    meshes = []
    for kind in (WORK, TRAVEL):
        keep = np.flatnonzero(path.kind == kind)
        n = keep.size
        cells = np.column_stack([np.full(n, 2), np.arange(n), np.arange(n, 2 * n)]).ravel()
        mesh = pv.PolyData(np.vstack([path.start[keep], path.end[keep]]), lines=cells)
        if kind == WORK:
            mesh.cell_data[color.by] = color.values[keep]
            w = path.op.waypoints
            a, b = np.asarray(w["a"], float), np.asarray(w["b"], float)
            if np.any(a != 0) or np.any(b != 0):
                from .analysis import tool_vectors

                rows = path.move_rows[path.move_of[keep]]
                mesh.cell_data["tool_vector"] = tool_vectors(a[rows], b[rows])
        meshes.append(mesh)
    return meshes[0], meshes[1]


def _glyphs(pv, mesh: "pv.PolyData", size: float) -> "pv.PolyData":
    """Arrows along the tool direction at up to ``_MAX_GLYPHS`` segments."""
    centers = mesh.cell_centers()
    step = max(1, centers.n_points // _MAX_GLYPHS)
    picked = pv.PolyData(centers.points[::step])
    picked["tool_vector"] = mesh.cell_data["tool_vector"][::step]
    return picked.glyph(orient="tool_vector", scale=False, factor=size, geom=pv.Arrow())


def fitted_camera(camera: "str | Camera", path: Toolpath, aspect: float) -> Camera:
    """A Camera as given, or a named one (:data:`gcodekit.view.CAMERAS`) framing the work of ``path`` tightly."""
    return camera if isinstance(camera, Camera) else Camera.named(camera).fitted(path, aspect)


def plot_operation(op: "Operation", scalars: str | None = None, *, show_travel: bool = False,
                   tool_vectors: bool = False, off_screen: bool = True, screenshot: str | os.PathLike | None = None,
                   camera: "str | Camera" = "iso", window_size: tuple[int, int] = (1200, 900), line_width: float = 2.0,
                   cmap: str | None = None, background: str = "white",
                   scalar_bar: bool = True) -> np.ndarray | None:
    """Draw the toolpath of an emulated operation in 3D with PyVista.

    Parameters
    ----------
    op : Operation
    scalars : str, default: None
        Colour by ``feature``, ``speed``, ``layer``, ``time`` or any waypoint
        column (see :func:`gcodekit.view.coloring`); None picks ``feature``
        when the program marks features, else ``layer`` (additive) or ``feed``.
    show_travel : bool, default: False
        Also draw the moves that lay no material (rapids for a mill), grey.
    tool_vectors : bool, default: False
        Arrows along the head direction (5-axis DED programs).
    off_screen : bool, default: True
        Render without a window; False opens an interactive one.
    screenshot : path, default: None
        Write a PNG of the picture there.
    camera : {"iso", "top", "front", "side"} or Camera, default: "iso"
        Orthographic; a name frames the work tightly, a :class:`gcodekit.view.Camera` is taken as it is
        (the notebook viewer's ``viewer.camera`` gives the viewer's picture).
    cmap : str, default: None
        A matplotlib colormap instead of the shared palette (viridis, or the category colours).
    scalar_bar : bool, default: True
        Draw the colour bar (the legend of a categorical scalar).

    Returns
    -------
    The image as an (height, width, 3) array when off-screen, else None.
    """
    if not isinstance(camera, Camera):
        Camera.named(camera)  # a bad name fails before any work
    if not _is_emulated(op):
        raise ValueError(f"{op.file}: plot_operation needs an emulated operation (use gcode_to_operation)")
    from .export.vtk import import_pyvista

    pv = import_pyvista()
    path = Toolpath.of(op)
    scalars = scalars or default_coloring(op)
    color = coloring(path, scalars)
    mesh, travel = toolpath_polydata(path, color)
    if mesh.n_cells == 0 and (travel.n_cells == 0 or not show_travel):
        raise NothingToShowError(f"{op.file}: nothing to draw (no {'deposition' if op.process == 'additive' else 'feed'} "
                                 "moves)")
    plotter = pv.Plotter(off_screen=off_screen, window_size=list(window_size))
    plotter.set_background(background)
    categories = color.categories
    bar: dict[str, Any] = dict(title=color.title, color="black", vertical=True,
                               position_x=0.88, position_y=0.1, height=0.8, width=0.04,
                               title_font_size=18, label_font_size=14,
                               fmt="%.0f" if categories else "%.4g")
    # lines unlit: a segment shows its colour as the other pictures do, whichever way it faces
    kwargs: dict[str, Any] = dict(scalars=scalars, line_width=line_width, scalar_bar_args=bar, lighting=False,
                                  show_scalar_bar=scalar_bar, cmap=cmap or color.cmap(),
                                  clim=list(color.value_range(path.kind == WORK)))
    if categories:
        # one colour per category index, whichever indices the work has (PyVista's categories=True would
        # number the present values afresh and shift the colours)
        kwargs.update(clim=[-0.5, len(categories) - 0.5], n_colors=len(categories),
                      annotations={float(k): name for k, name in enumerate(categories)})
        bar.update(n_labels=0, n_colors=len(categories))
    else:
        kwargs["n_colors"] = 256
    if mesh.n_cells:
        plotter.add_mesh(mesh, **kwargs)
    if show_travel and travel.n_cells:
        plotter.add_mesh(travel, color=TRAVEL_COLOR, line_width=max(line_width / 2, 1.0), lighting=False)
    if tool_vectors and "tool_vector" in mesh.cell_data:
        lo, hi = path.bounds()
        plotter.add_mesh(_glyphs(pv, mesh, 0.04 * float(np.linalg.norm(hi - lo))), color="#d62728")
    _place(plotter, path, fitted_camera(camera, path, window_size[0] / window_size[1]))
    if not off_screen:
        plotter.show()
        return None
    image = plotter.screenshot(None if screenshot is None else str(screenshot), return_img=True)
    plotter.close()
    return image


def _is_emulated(op) -> bool:
    return getattr(op, "waypoints", None) is not None


def _place(plotter, path: Toolpath, camera: Camera) -> None:
    """Look at the work as ``camera`` says: orthographic, the work's sphere filling the height at zoom 1."""
    middle, radius = path.frame()
    centre, half = camera.view(middle, radius)
    _, up, eye = camera.axes()
    plotter.enable_parallel_projection()
    plotter.camera.focal_point = tuple(centre)
    plotter.camera.position = tuple(centre + eye * radius * 10)
    plotter.camera.up = tuple(up)
    plotter.camera.parallel_scale = half
    plotter.camera.clipping_range = (radius * 8, radius * 12)


def draw_toolpath(ax: "Axes", path: Toolpath, color: Coloring, camera: Camera, segments: np.ndarray, *,
                  work_width: float = 1.0, travel_width: float = 0.5, absolute: bool = False,
                  lod: bool = False) -> tuple[float, float]:
    """Draw ``segments`` of ``path`` on a 2D matplotlib Axes as ``camera`` sees them; returns the colour scale.

    Far segments are drawn first (a painter's order), so nearer ones cover
    them, as a depth buffer would.  The Axes' limits frame the work as the
    camera does (call ``set_xlim``/``set_ylim`` to frame otherwise);
    ``absolute`` keeps machine coordinates on the axes (for a ``top`` view:
    X and Y in mm), else they are mm from the point looked at.  ``lod``
    draws only what the Axes' pixels show, joined into polylines
    (:mod:`gcodekit.view.lod`): the same picture to the eye, drawn in a
    fraction of the time when there are many segments.
    """
    from matplotlib.collections import LineCollection, PathCollection
    from matplotlib.path import Path

    from .view.lod import last_drawn, painter_order, polylines

    right, up, eye = camera.axes()
    middle, radius = path.frame()
    centre, half = camera.view(middle, radius)
    origin = np.zeros(3) if absolute else centre
    rgb, vmin, vmax = color.segment_rgb(path, segments)
    p0, p1 = path.start[segments] - origin, path.end[segments] - origin
    order = painter_order(p0, p1, eye) if lod else np.argsort((p0 + p1) @ eye, kind="stable")
    lines = np.stack([np.column_stack([p0 @ right, p0 @ up]), np.column_stack([p1 @ right, p1 @ up])], axis=1)
    widths = np.where(path.kind[segments] == WORK, work_width, travel_width)[order]
    x0, y0 = (centre - origin) @ right, (centre - origin) @ up
    box = ax.get_position()
    fig_w, fig_h = ax.figure.get_size_inches()
    aspect = (box.width * fig_w) / (box.height * fig_h)
    xlim, ylim = (x0 - half * aspect, x0 + half * aspect), (y0 - half, y0 + half)
    lines, rgb = lines[order], rgb[order]
    if lod:
        dpi = ax.figure.dpi
        size = np.array([box.width * fig_w * dpi, box.height * fig_h * dpi])
        pixels = (lines - [xlim[0], ylim[0]]) * (size / [xlim[1] - xlim[0], ylim[1] - ylim[0]])
        style = np.column_stack([rgb, widths])
        runs = polylines(lines[:, 0], lines[:, 1], style,
                         last_drawn(pixels[:, 0], pixels[:, 1], *np.ceil(size).astype(int)))
        vertices, starts, first = runs.batches(style[runs.first])
        paths = [Path(v, np.where(s, Path.MOVETO, Path.LINETO).astype(Path.code_type))
                 for v, s in zip(vertices, starts)]
        batch = runs.first[first]
        # the limits are set below: no extents of every path (autolim)
        ax.add_collection(PathCollection(paths, facecolors="none", edgecolors=rgb[batch], linewidths=widths[batch]),
                          autolim=False)
    else:
        ax.add_collection(LineCollection(lines, colors=rgb, linewidths=widths))
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    return vmin, vmax


def add_legend(fig: "Figure", color: Coloring, path: Toolpath, segments: np.ndarray, vmin: float, vmax: float, *,
               rect: tuple[float, float, float, float] = (0.82, 0.1, 0.03, 0.8), fontsize: float = 8) -> None:
    """The colour bar, or one swatch per category present among the work of ``segments``."""
    work = segments[path.kind[segments] == WORK]
    if color.categories is not None:
        import matplotlib.patches as mpatches

        used = color.used(work)
        rgb = color.rgb(np.asarray(used), 0, 1)
        handles = [mpatches.Patch(color=rgb[k], label=color.categories[c]) for k, c in enumerate(used)]
        fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(rect[0] - 0.04, rect[1] + rect[3] + 0.05),
                   fontsize=fontsize, frameon=False, title=color.title, title_fontsize=fontsize + 1)
        return
    if vmax <= vmin:  # one value: a swatch that says so, not a scale over a range nothing has
        fig.legend(handles=[_one_value_patch(color, vmin)], loc="upper right",  # its title can be long
                   bbox_to_anchor=(0.99, rect[1] + rect[3] + 0.05), fontsize=fontsize, frameon=False,
                   title=color.title, title_fontsize=fontsize + 1)
        return
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    cax = fig.add_axes(list(rect))
    bar = fig.colorbar(ScalarMappable(Normalize(vmin, vmax), color.cmap()), cax=cax)
    bar.set_label(color.title, fontsize=fontsize + 1)
    bar.ax.tick_params(labelsize=fontsize)


def _one_value_patch(color: Coloring, value: float):
    """The legend entry of a colouring whose work moves all have ``value``, in the colour they are drawn in."""
    import matplotlib.patches as mpatches

    return mpatches.Patch(color=color.rgb(np.array([value]), value, value)[0], label=f"every move: {value:g}")


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
    path = Toolpath.of(source, "layer")
    in_layer = path.segment_group == layer
    work = np.flatnonzero(in_layer & (path.kind == WORK))
    if work.size == 0:
        raise NothingToShowError(f"{op.file}: layer {layer} has no deposition moves")
    if ax is None:
        import matplotlib.pyplot as plt

        ax = plt.subplots(figsize=(7, 6))[1]
    color = coloring(path, scalars)
    rgb, vmin, vmax = color.segment_rgb(path, work)
    xy = lambda p, keep: p[keep][:, :2]  # noqa: E731
    ax.add_collection(LineCollection(np.stack([xy(path.start, work), xy(path.end, work)], axis=1), colors=rgb,
                                     linewidths=line_width))
    if show_travel:
        travel = np.flatnonzero(in_layer & (path.kind == TRAVEL))
        ax.add_collection(LineCollection(np.stack([xy(path.start, travel), xy(path.end, travel)], axis=1),
                                         linewidths=0.5, colors=TRAVEL_COLOR, linestyles="dashed"))
    if color.categories is not None:
        import matplotlib.lines as mlines

        used = color.used(work)
        handles = [mlines.Line2D([], [], color=color.rgb(np.array([k]), 0, 1)[0], label=color.categories[k])
                   for k in used]
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    elif vmax <= vmin:
        ax.legend(handles=[_one_value_patch(color, vmin)], loc="upper left", bbox_to_anchor=(1.01, 1.0),
                  fontsize="small", frameon=False, title=color.title)
    else:
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import Normalize

        ax.figure.colorbar(ScalarMappable(Normalize(vmin, vmax), color.cmap()), ax=ax, label=color.title)
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("X (mm)")
    ax.set_ylabel("Y (mm)")
    ax.set_title(f"{os.path.basename(op.file)}: layer {layer}")
    return ax
