"""The live trame views without a browser: their server on gcodekit's own loop, the bead view's slider and PNG."""

import threading
import urllib.request
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("trame_pyvista")
pytest.importorskip("ipywidgets")

import gcodekit  # noqa: E402
from gcodekit.widgets import trame_view  # noqa: E402

EXAMPLES = Path(__file__).parents[1] / "examples"


def _src(view) -> str:
    return view.view.value.split('src="', 1)[1].split('"', 1)[0].replace("&amp;", "&").replace("localhost", "127.0.0.1")


@pytest.fixture(scope="module")
def beads():
    from gcodekit.widgets import BeadView

    return BeadView(gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode"), size=(320, 240))


def test_the_public_trame_pyvista_calls_the_views_rest_on_exist():
    # the views use only these two public functions of trame-pyvista (no private loop of its own)
    from trame_pyvista import jupyter

    assert callable(jupyter.launch_server) and callable(jupyter.show_trame)
    source = Path(trame_view.__file__).read_text()
    assert "jupyter._" not in source and "_server_loop" not in source.replace("on_trame_loop", "")


def test_the_server_runs_on_gcodekits_own_loop_and_serves_the_view(beads):
    loop = trame_view.trame_loop()
    threads = [t for t in threading.enumerate() if t.name == "gcodekit-trame"]
    assert len(threads) == 1 and loop.is_running()

    def server():
        from trame_pyvista.widgets import get_server

        return get_server(trame_view.SERVER_NAME)

    srv = trame_view.on_trame_loop(server)
    assert srv.running
    with urllib.request.urlopen(_src(beads), timeout=30) as page:
        assert page.status == 200 and b"<html" in page.read(2000).lower()
    # a second view shares the server
    from gcodekit.cut import ToolLibrary
    from gcodekit.widgets import PartView

    part = PartView(gcodekit.gcode_to_operation(EXAMPLES / "bracket_mill.ngc"),
                    tools=ToolLibrary.read(EXAMPLES / "tools" / "bracket_mill.toml"), size=(320, 240))
    assert _src(part).split("/index")[0] == _src(beads).split("/index")[0]
    part.show_move(1)
    assert 'data-move="1"' in part.status.value and "removed 0.0 mm³" in part.status.value


def test_the_bead_slider_shows_the_beads_up_to_a_move(beads):
    ink = lambda image: (image.min(axis=2) < 235).mean()  # noqa: E731
    whole = beads.screenshot()
    assert ink(whole) > 0.1
    beads.show_move(1)
    first = beads.screenshot()
    assert ink(first) < 0.05 * ink(whole)
    assert 'data-move="1"' in beads.status.value and "layer 0" in beads.status.value
    # the live view's blocks: the first shows the first move's triangles, the rest are hidden
    shown = beads._shown
    assert shown[0] == beads._counts[0] == beads._meshes[0].n_cells and not any(shown[1:])
    assert [beads.plotter.actors[f"beads{k}"].visibility for k in range(len(shown))] == [True] + [False] * (
        len(shown) - 1)
    # half way: the blocks before are whole, the one the move ends in is cut, the rest hidden
    middle = beads.n_moves // 2
    beads.show_move(middle)
    count = int(beads._counts[middle - 1])
    assert sum(beads._shown) == count
    k = int(np.searchsorted(beads._bounds, count, side="left")) - 1
    assert beads._meshes[k].n_cells == count - beads._bounds[k]
    assert all(m.n_cells == beads._bounds[j + 1] - beads._bounds[j] for j, m in enumerate(beads._meshes[:k]))
    beads.show_move(beads.n_moves)
    assert sum(beads._shown) == len(beads.tubes.triangles)
    # laid so far: the filament volume of the depositing moves, the whole part at the end
    assert f"laid {beads.part.volume:,.1f} mm³" in beads.status.value
    assert "External perimeter" in beads.status.value  # the features' legend


def test_the_display_carries_a_png(beads):
    import base64
    import io

    from PIL import Image

    bundle = beads._repr_mimebundle_()
    image = np.asarray(Image.open(io.BytesIO(base64.b64decode(bundle["image/png"]))).convert("RGB"))
    assert image.shape == (240, 320, 3) and (image.min(axis=2) < 235).mean() > 0.1
    assert "application/vnd.jupyter.widget-view+json" in bundle and "BeadView" in bundle["text/plain"]


def test_a_program_that_lays_nothing_is_a_clear_error():
    from gcodekit.widgets import BeadView

    with pytest.raises(ValueError, match="no beads to show"):
        BeadView(gcodekit.gcode_to_operation("G1 X10 F600\n", "marlin"))
