#!/usr/bin/python3
"""Regenerate tests/golden/freecad/api.json: FreeCAD 0.20's answers to the scripted API cases (freecad_cases.py).

Run with Debian's FreeCAD (``apt-get install freecad-python3``) and its
interpreter:

    /usr/bin/python3 tests/golden/freecad/regenerate_freecad.py

Each case runs in a forked child with a clean HOME, because FreeCAD 0.20.2
aborts the whole process on some inputs (recorded as ``{"abort": signal}``).
The file names FreeCAD's version; the tests need neither FreeCAD nor this
script.
"""

import json
import os
import pathlib
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
FREECAD_LIB = "/usr/lib/freecad-python3/lib"
sys.path.insert(0, str(HERE))
from freecad_cases import CASES, plain  # noqa: E402  (beside this script)


def run(code, env):
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        try:
            scope = dict(env)
            exec(code, scope)
            out = {"result": plain(scope["result"])}
        except Exception as exc:  # FreeCAD's Python-level errors
            out = {"error": type(exc).__name__}
        os.write(w, json.dumps(out).encode())
        os._exit(0)
    os.close(w)
    data = b""
    while True:
        chunk = os.read(r, 1 << 16)
        if not chunk:
            break
        data += chunk
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status) or not data:
        return {"abort": os.WTERMSIG(status) if os.WIFSIGNALED(status) else "no output"}
    return json.loads(data)


def main():
    home = tempfile.mkdtemp(prefix="freecad-golden.")
    os.environ.update(HOME=home, XDG_CONFIG_HOME=home + "/.config", XDG_DATA_HOME=home + "/.local/share",
                      XDG_CACHE_HOME=home + "/.cache")
    sys.path.append(FREECAD_LIB)
    import FreeCAD
    import Path

    def box(p):
        b = p.BoundBox
        return [b.XMin, b.YMin, b.ZMin, b.XMax, b.YMax, b.ZMax]

    env = {"Path": Path, "App": FreeCAD, "length": lambda p: p.Length, "box": box,
           "same": lambda p: [p.Length, box(p)]}
    version = ".".join(FreeCAD.Version()[:3])
    answers = {name: run(code, env) for name, code in CASES.items()}
    out = {"freecad": version, "generated_by": "tests/golden/freecad/regenerate_freecad.py", "cases": answers}
    (HERE / "api.json").write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    print(f"FreeCAD {version}: {len(answers)} cases, "
          f"{sum('abort' in a for a in answers.values())} aborts, {sum('error' in a for a in answers.values())} errors")


if __name__ == "__main__":
    main()
