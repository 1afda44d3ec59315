"""Benchmark: a layer-slider step of LayerViewer and its linked VelocityPlot, in a real browser.

The acceptance benchmark of the widgets issue: on ``cylinder_marlin2.gcode``
(130 k drawn moves) and ``cube20_marlin2.gcode``, a layer-slider step measured
in the browser from the key press to the new picture, median at most 150 ms;
the ``VelocityPlot`` redraw following the linked range at most 150 ms.

How: JupyterLab is started here and driven by Playwright in Debian's Chromium
(SwiftShader draws WebGL on the CPU: no GPU on this machine).  A notebook
shows ``LayerViewer(program)`` and ``VelocityPlot(program).link(viewer)``;
the upper handle of the layer slider gets focus and the arrow key is pressed
``--steps`` times, one press every ``--pause`` ms, then the right arrow as
many times (steps down the part, then up).  In the page, a capturing
``keydown`` listener stamps the press; a ``MutationObserver`` stamps the
view's status label, which the view rewrites right after its draw call
(*drawn*), and the first animation frame after that (*shown*: the compositor
took the frame with the new picture); another observer stamps the plot's
label after its redraw (*plot*; the kernel computes the new range, so this
is a round trip).  The peer, side by side: the same step drawn in the kernel
as a PNG (``LayerViewer.png()``, matplotlib), what a viewer showing an image
per step (``ipywidgets.Image``) pays before the transfer.

Examples
--------
::

    python benchmarks/bench_widgets.py                # both programs, about 2 minutes
    python benchmarks/bench_widgets.py --steps 10 --files ../shared/corpus/fff/cube20_marlin2.gcode
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))  # the JupyterLab + Playwright harness of the browser tests
CORPUS = REPO.parent / "shared" / "corpus" / "fff"
FILES = [CORPUS / "cylinder_marlin2.gcode", CORPUS / "cube20_marlin2.gcode"]
LIMIT_MS = 150.0

PROBE = """() => {
  window.gk = { key: null, drawn: [], shown: [], plot: [], plotKey: null };
  document.addEventListener('keydown', () => { window.gk.key = performance.now(); window.gk.plotKey = window.gk.key; }, true);
  new MutationObserver(() => {
    const t0 = window.gk.key;
    if (t0 === null) return;
    window.gk.key = null;
    window.gk.drawn.push(performance.now() - t0);
    requestAnimationFrame(() => window.gk.shown.push(performance.now() - t0));
  }).observe(document.querySelector('.gk-status'), { attributes: true, attributeFilter: ['data-frame'] });
  new MutationObserver(() => {
    const t0 = window.gk.plotKey;
    if (t0 === null) return;
    window.gk.plotKey = null;
    window.gk.plot.push(performance.now() - t0);
  }).observe(document.querySelector('.gk-plot-status'), { attributes: true, attributeFilter: ['data-frame'] });
}"""


def notebook(program: Path, out: Path) -> None:
    import nbformat
    from nbformat.v4 import new_code_cell, new_notebook

    nb = new_notebook(cells=[new_code_cell(
        "import gcodekit\nfrom gcodekit.widgets import LayerViewer, VelocityPlot\n"
        f"op = gcodekit.gcode_to_operation({program.name!r})\nviewer = LayerViewer(op)\n"
        "display(viewer, VelocityPlot(op).link(viewer))")])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, out)


def browser_steps(program: Path, steps: int, pause_ms: int) -> dict:
    from jupyter_browser import browser_page, jupyter_lab, open_and_run

    root = Path(tempfile.mkdtemp(prefix="gcodekit-bench-"))
    try:
        shutil.copy(program, root / program.name)
        notebook(program, root / "bench.ipynb")
        with jupyter_lab(root) as url, browser_page() as page:
            open_and_run(page, url, "bench.ipynb")
            page.wait_for_selector(".gk-status[data-frame]", state="attached", timeout=60_000)
            page.wait_for_selector(".gk-plot-status[data-frame]", state="attached", timeout=60_000)
            page.wait_for_timeout(1000)
            page.evaluate(PROBE)
            page.locator(".noUi-handle-upper").first.focus()
            for key in ("ArrowLeft", "ArrowRight"):
                for _ in range(steps):
                    page.keyboard.press(key)
                    page.wait_for_timeout(pause_ms)
            result = page.evaluate("window.gk")
            result["segments"] = int(page.get_attribute(".gk-status", "data-segments"))
            result["errors"] = list(page.console_errors)
            return result
    finally:
        shutil.rmtree(root, ignore_errors=True)


def peer_png(program: Path, steps: int) -> list[float]:
    """The same steps drawn as PNGs in Python (an image-per-step viewer's cost before the transfer)."""
    import gcodekit
    from gcodekit.widgets import LayerViewer

    viewer = LayerViewer(gcodekit.gcode_to_operation(program))
    top = viewer.layers.max
    times = []
    for k in range(1, min(steps, 5) + 1):
        viewer.layers.value = (0, top - k)
        t0 = time.perf_counter()
        viewer.png()
        times.append((time.perf_counter() - t0) * 1000)
    return times


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--files", nargs="+", type=Path, default=FILES)
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--pause", type=int, default=400, help="ms between key presses (default: 400)")
    parser.add_argument("--quick", action="store_true", help="smoke run: cube20 only, 5 steps each way")
    parser.add_argument("--json", metavar="OUT", help="also write the medians as JSON")
    args = parser.parse_args(argv)
    if args.quick:
        args.files, args.steps = [FILES[1]], 5
    t0 = time.perf_counter()
    import gcodekit  # noqa: F401

    print(f"import gcodekit: {(time.perf_counter() - t0) * 1000:.0f} ms")
    failed = False
    figures = []
    for program in args.files:
        r = browser_steps(program, args.steps, args.pause)
        png = peer_png(program, args.steps)
        med = {k: statistics.median(r[k]) if r[k] else float("nan") for k in ("drawn", "shown", "plot")}
        print(f"{program.name}: {len(r['drawn'])} steps, {r['segments']} segments drawn at the end")
        for k, label in (("drawn", "key press to draw call"), ("shown", "key press to the frame shown"),
                         ("plot", "key press to VelocityPlot redrawn")):
            values = r[k]
            half = len(values) // 2
            print(f"  {label:36s} median {med[k]:6.0f} ms   max {max(values, default=float('nan')):6.0f} ms"
                  f"   (down {statistics.median(values[:half] or [0]):.0f}, up {statistics.median(values[half:] or [0]):.0f})")
        print(f"  peer: the step as a PNG in Python   median {statistics.median(png):6.0f} ms "
              f"(ratio {statistics.median(png) / med['shown']:.1f}x the browser's step)")
        if r["errors"]:
            print(f"  browser console errors: {r['errors']}")
        ok = med["shown"] <= LIMIT_MS and med["plot"] <= LIMIT_MS
        figures.append({"file": program.name, "steps": len(r["drawn"]), "segments": r["segments"],
                        **{f"{k}_ms": med[k] for k in med}, "peer_png_ms": statistics.median(png),
                        "limit_ms": LIMIT_MS, "pass": ok})
        failed |= not ok
        print(f"  {'PASS' if ok else 'FAIL'}: medians within {LIMIT_MS:.0f} ms")
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=2) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
