"""Benchmark: LayerViewer and its linked VelocityPlot in a real browser: opening, bytes sent, a layer-slider step.

The acceptance benchmark of the widgets issues: on ``cylinder_marlin2.gcode``
(137 k segments), ``cube20_marlin2.gcode`` and ``plate150_marlin2.gcode.gz``
(3.1 M lines, 250 layers, 3 M segments), the two widgets open within 5 s of
the cell running (the program already emulated and planned), the browser is
sent a bounded amount, and a layer-slider step, from the key press to the
new picture, takes at most 150 ms (median); the ``VelocityPlot`` redraw
following the linked range at most 150 ms.

How: JupyterLab is started here and driven by Playwright in Debian's Chromium
(SwiftShader draws WebGL on the CPU: no GPU on this machine).  A notebook
reads the program in its first cell; its second cell notes the wall clock,
makes ``LayerViewer(op)`` and ``VelocityPlot(op).link(viewer)`` and
displays them.  *Open* is the time from that clock reading to the first
frame the browser shows of each widget (an observer in the page stamps the
view's status label when the first picture is drawn, and the animation frame
after it); both clocks are this machine's.  The kernel's wall and CPU
time (its threads included) for each widget and for the display, and the
load average, are printed beside: the machine is shared, and its load shows
in the wall times.  *Bytes* are the kernel's
websocket frames the page receives: while the cell runs (the widgets'
state, their PNGs) and during the steps (layers sent on demand).

Then the upper handle of the layer slider gets focus and the arrow key is
pressed ``--steps`` times, one press every ``--pause`` ms, then the right
arrow as many times (steps down the part, then up).  In the page, a
capturing ``keydown`` listener stamps the press; a ``MutationObserver``
stamps the view's status label, which the view rewrites right after its draw
call (*drawn*), and the first animation frame after that (*shown*: the
compositor took the frame with the new picture); *detailed* is the first
shown frame whose top layer is drawn at full detail (the same frame unless
the view first showed that layer from its overview while the layer's own
segments were on their way).  Another observer stamps the plot's label after
its redraw (*plot*; the kernel computes the new range, so this is a round
trip).  The peer, side by side: the same step drawn in the kernel as a PNG
(``LayerViewer.png()``, matplotlib), what a viewer showing an image per step
(``ipywidgets.Image``) pays before the transfer.

Examples
--------
::

    python benchmarks/bench_widgets.py                # the three programs, about 5 minutes
    python benchmarks/bench_widgets.py --steps 10 --files ../shared/corpus/fff/cube20_marlin2.gcode
    python benchmarks/bench_widgets.py --json out/bench_widgets.json
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))  # the JupyterLab + Playwright harness of the browser tests
CORPUS = REPO.parent / "shared" / "corpus" / "fff"
FILES = [CORPUS / "cylinder_marlin2.gcode", CORPUS / "cube20_marlin2.gcode", CORPUS / "plate150_marlin2.gcode.gz"]
LIMIT_MS = 150.0
OPEN_LIMIT_S = 5.0

#: Installed before the cells run: the wall clock of each widget's first drawn and shown frame.
OPEN_PROBE = """() => {
  window.gkOpen = {};
  new MutationObserver((records) => {
    for (const r of records) {
      const name = r.target.classList.contains('gk-status') ? 'viewer'
        : r.target.classList.contains('gk-plot-status') ? 'plot' : null;
      if (name === null || name in window.gkOpen) continue;
      window.gkOpen[name] = Date.now();
      requestAnimationFrame(() => { window.gkOpen[name + 'Shown'] = Date.now(); });
    }
  }).observe(document.body, { subtree: true, attributes: true, attributeFilter: ['data-frame'] });
}"""

#: Installed before the steps: each key press, the view's next frame (and its next full-detail frame), the plot's.
PROBE = """() => {
  window.gk = { key: null, detailKey: null, drawn: [], shown: [], detailed: [], plot: [], plotKey: null };
  document.addEventListener('keydown', () => {
    const now = performance.now();
    window.gk.key = window.gk.detailKey = window.gk.plotKey = now;
  }, true);
  const status = document.querySelector('.gk-status');
  new MutationObserver(() => {
    const t0 = window.gk.key, t1 = window.gk.detailKey;
    const full = status.dataset.detail === undefined || status.dataset.detail === 'full';
    if (t0 !== null) {
      window.gk.key = null;
      window.gk.drawn.push(performance.now() - t0);
      requestAnimationFrame(() => window.gk.shown.push(performance.now() - t0));
    }
    if (t1 !== null && full) {
      window.gk.detailKey = null;
      requestAnimationFrame(() => window.gk.detailed.push(performance.now() - t1));
    }
  }).observe(status, { attributes: true, attributeFilter: ['data-frame'] });
  new MutationObserver(() => {
    const t0 = window.gk.plotKey;
    if (t0 === null) return;
    window.gk.plotKey = null;
    window.gk.plot.push(performance.now() - t0);
  }).observe(document.querySelector('.gk-plot-status'), { attributes: true, attributeFilter: ['data-frame'] });
}"""

#: The second cell: the clock read, the widgets made and shown, the kernel's own times printed.
OPEN_CELL = """import os, time
load = os.getloadavg()[0]
t0, c0 = time.time(), time.process_time()
viewer = LayerViewer(op)
t1, c1 = time.time(), time.process_time()
plot = VelocityPlot(op).link(viewer)
t2, c2 = time.time(), time.process_time()
display(viewer, plot)
t3, c3 = time.time(), time.process_time()
print(f"gk-times {t0:.3f} {t1 - t0:.3f} {t2 - t1:.3f} {t3 - t2:.3f} {c1 - c0:.3f} {c2 - c1:.3f} {c3 - c2:.3f} {load:.2f}")"""


def notebook(program: Path, out: Path) -> None:
    import nbformat
    from nbformat.v4 import new_code_cell, new_notebook

    nb = new_notebook(cells=[
        new_code_cell("import gcodekit\nfrom gcodekit.widgets import LayerViewer, VelocityPlot\n"
                      f"op = gcodekit.gcode_to_operation({program.name!r})"),
        new_code_cell(OPEN_CELL)])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, out)


class Traffic:
    """Bytes of the kernel's websocket frames received by the page."""

    def __init__(self, page):
        self.bytes = 0
        page.on("websocket", self._socket)

    def _socket(self, ws) -> None:
        if "/channels" in ws.url:
            ws.on("framereceived", self._frame)

    def _frame(self, payload) -> None:
        self.bytes += len(payload)


def browser_steps(program: Path, steps: int, pause_ms: int) -> dict:
    from jupyter_browser import browser_page, jupyter_lab, open_and_run

    root = Path(tempfile.mkdtemp(prefix="gcodekit-bench-"))
    try:
        shutil.copy(program, root / program.name)
        notebook(program, root / "bench.ipynb")
        with jupyter_lab(root) as url, browser_page() as page:
            traffic = Traffic(page)
            marks = {}

            def before_run(page):
                page.evaluate(OPEN_PROBE)
                marks["start"] = traffic.bytes

            open_and_run(page, url, "bench.ipynb", before_run=before_run)
            try:
                page.wait_for_selector(".gk-status[data-frame]", state="attached", timeout=120_000)
                page.wait_for_selector(".gk-plot-status[data-frame]", state="attached", timeout=120_000)
            except Exception as exc:
                outputs = page.locator(".jp-OutputArea-output").all_inner_texts()
                raise RuntimeError(f"no picture: cell outputs {outputs}, console errors {page.console_errors}") from exc
            page.wait_for_timeout(1000)
            opened = page.evaluate("window.gkOpen")
            times = page.locator(".jp-OutputArea-output:has-text('gk-times')").inner_text().split()
            t0, kernel = float(times[1]), [float(v) for v in times[2:9]]
            result = {"open_viewer_s": opened["viewerShown"] / 1000 - t0, "open_plot_s": opened["plotShown"] / 1000 - t0,
                      "kernel_viewer_s": kernel[0], "kernel_plot_s": kernel[1], "kernel_display_s": kernel[2],
                      "kernel_viewer_cpu_s": kernel[3], "kernel_plot_cpu_s": kernel[4], "kernel_display_cpu_s": kernel[5],
                      "load_at_open": kernel[6],
                      "open_bytes": traffic.bytes - marks["start"]}
            page.evaluate(PROBE)
            before_steps = traffic.bytes
            page.locator(".noUi-handle-upper").first.focus()
            for key in ("ArrowLeft", "ArrowRight"):
                for _ in range(steps):
                    page.keyboard.press(key)
                    page.wait_for_timeout(pause_ms)
            page.wait_for_timeout(1000)
            result.update(page.evaluate("window.gk"))
            result["step_bytes"] = traffic.bytes - before_steps
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
    for k in range(1, steps + 1):
        viewer.layers.value = (0, top - k)
        t0 = time.perf_counter()
        viewer.png()
        times.append((time.perf_counter() - t0) * 1000)
    return times


def report(program: Path, r: dict, png: list[float]) -> bool:
    """Print one program's figures; whether they meet the limits."""
    med = {k: statistics.median(r[k]) if r[k] else float("nan") for k in ("drawn", "shown", "detailed", "plot")}
    print(f"{program.name}: {len(r['drawn'])} steps, {r['segments']} segments drawn at the end")
    print(f"  open: first picture of LayerViewer {r['open_viewer_s']:.2f} s, of VelocityPlot {r['open_plot_s']:.2f} s "
          f"after the cell started (kernel: viewer {r['kernel_viewer_s']:.2f} s, plot {r['kernel_plot_s']:.2f} s, "
          f"display {r['kernel_display_s']:.2f} s; CPU {r['kernel_viewer_cpu_s']:.2f}, {r['kernel_plot_cpu_s']:.2f} "
          f"and {r['kernel_display_cpu_s']:.2f} s, threads included; load average {r['load_at_open']:.1f})")
    print(f"  bytes received from the kernel: {r['open_bytes'] / 1e6:.2f} MB while the cell ran, "
          f"{r['step_bytes'] / 1e6:.2f} MB during the steps")
    for k, label in (("drawn", "key press to draw call"), ("shown", "key press to the frame shown"),
                     ("detailed", "key press to the full-detail frame"),
                     ("plot", "key press to VelocityPlot redrawn")):
        values = r[k]
        half = len(values) // 2
        print(f"  {label:36s} median {med[k]:6.0f} ms   max {max(values, default=float('nan')):6.0f} ms"
              f"   (down {statistics.median(values[:half] or [0]):.0f}, up {statistics.median(values[half:] or [0]):.0f})")
    if png:
        print(f"  peer: the step as a PNG in Python   median {statistics.median(png):6.0f} ms "
              f"(ratio {statistics.median(png) / med['shown']:.1f}x the browser's step)")
    if r["errors"]:
        print(f"  browser console errors: {r['errors']}")
    ok = (med["shown"] <= LIMIT_MS and med["plot"] <= LIMIT_MS and r["open_viewer_s"] <= OPEN_LIMIT_S
          and r["open_plot_s"] <= OPEN_LIMIT_S)
    print(f"  {'PASS' if ok else 'FAIL'}: step medians within {LIMIT_MS:.0f} ms, both open within {OPEN_LIMIT_S:.0f} s")
    return ok


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--files", nargs="+", type=Path, default=FILES)
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--pause", type=int, default=400, help="ms between key presses (default: 400)")
    parser.add_argument("--peer-steps", type=int, default=3, help="steps drawn as PNGs by the peer (0: none)")
    parser.add_argument("--quick", action="store_true", help="smoke run: cube20 only, 5 steps each way")
    parser.add_argument("--json", metavar="OUT", type=Path,
                        help="also write each program's medians and figures here (a list, as run_all.py reads it)")
    args = parser.parse_args(argv)
    if args.quick:
        args.files, args.steps = [FILES[1]], 5
    t0 = time.perf_counter()
    import gcodekit  # noqa: F401

    print(f"import gcodekit: {(time.perf_counter() - t0) * 1000:.0f} ms")
    failed, figures = False, []
    for program in args.files:
        load_before = os.getloadavg()[0]
        r = browser_steps(program, args.steps, args.pause)
        r["load_before"], r["load_after"] = load_before, os.getloadavg()[0]
        print(f"load average {load_before:.1f} before, {r['load_after']:.1f} after (2 CPUs shared: wall times grow "
              "with it; the kernel's CPU times less)")
        png = peer_png(program, args.peer_steps) if args.peer_steps else []
        ok = report(program, r, png)
        failed |= not ok
        med = {k: statistics.median(r[k]) if r[k] else float("nan") for k in ("drawn", "shown", "detailed", "plot")}
        figures.append({"file": program.name, "steps": len(r["drawn"]), "segments": r["segments"],
                        **{f"{k}_ms": med[k] for k in med},
                        "peer_png_ms": statistics.median(png) if png else float("nan"), "limit_ms": LIMIT_MS,
                        "open_limit_s": OPEN_LIMIT_S, "pass": ok, **r, "peer_png_all_ms": png})
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=2) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
