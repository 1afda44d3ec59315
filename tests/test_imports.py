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


def test_import_loads_no_stage_until_a_name_is_used():
    """The front door holds the errors and limits; the pipeline and everything after it load on first use."""
    code = (
        "import sys, gcodekit\n"
        "print(','.join(sorted(m for m in sys.modules if m.startswith('gcodekit'))))\n"
        "gcodekit.gcode_to_operation\n"
        "print('gcodekit.pipeline' in sys.modules, 'gcodekit.visualize' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["gcodekit,gcodekit.errors,gcodekit.limits", "True", "False"]


def test_lazy_names_are_the_modules_own():
    import gcodekit
    import gcodekit.additive
    import gcodekit.pipeline
    import gcodekit.visualize

    assert gcodekit.gcode_to_operation is gcodekit.pipeline.gcode_to_operation
    assert gcodekit.AdditivePart is gcodekit.additive.AdditivePart
    assert gcodekit.visualize is sys.modules["gcodekit.visualize"]
    assert set(gcodekit.__all__) <= set(dir(gcodekit))
    try:
        gcodekit.no_such_name
    except AttributeError as exc:
        assert "no_such_name" in str(exc)
    else:
        raise AssertionError("an unknown name must raise AttributeError")


#: What ``gcodekit info`` does not need: pictures, exporters, the report's batch (worker pools), ctypes' search,
#: masked arrays (``np.unique`` without ``return_inverse`` imports them: 20 ms).
NOT_FOR_INFO = HEAVY + ["gcodekit.visualize", "gcodekit.view", "gcodekit.additive", "gcodekit.analysis",
                        "gcodekit.export", "gcodekit.report.batch", "gcodekit.transpile", "gcodekit.cut",
                        "concurrent.futures", "multiprocessing", "ctypes.util", "numpy.ma"]


def test_info_loads_only_the_pipeline(tmp_path):
    program = tmp_path / "part.gcode"
    program.write_text(";FLAVOR:Marlin\nM83\nG1 Z0.2 F600\nG1 X10 Y10 E1 F1800\nG1 X20 E1\n")
    code = (
        "import sys\n"
        "from gcodekit.cli import main\n"
        f"status = main(['info', {str(program)!r}])\n"
        f"print('LOADED', ','.join(m for m in {NOT_FOR_INFO!r} if m in sys.modules), status)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    loaded = out.split("LOADED", 1)[1].split()
    assert loaded == ["0"], loaded  # nothing listed, exit status 0
    assert "part.gcode" in out and "layers" in out  # the summary was printed
