"""``import gcodekit`` loads NumPy only; pandas and heavier libraries load on first use."""

import subprocess
import sys

HEAVY = ["pandas", "pyvista", "vtk", "matplotlib", "ipywidgets", "anywidget", "trame", "jinja2", "tqdm", "hypothesis",
         "scipy"]


def test_import_is_light():
    code = (
        "import sys, gcodekit\n"
        f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_public_api_names():
    import gcodekit

    for name in ("gcode_to_operation", "gcode_file_to_dataframe", "Operation", "GcodeParser", "load_flavor",
                 "detect_flavor", "list_machines", "GcodeError"):
        assert hasattr(gcodekit, name)
