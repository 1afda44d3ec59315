#!/usr/bin/env python3
"""Make the slicer files of tests/golden/slicers/ with the slicers Debian packages.

    apt-get install --no-install-recommends prusa-slicer cura-engine cura
    python3 tests/golden/slicers/make_slicer_files.py

Two shapes (a 20 mm cube and a 20 mm x 10 mm cylinder of 96 facets), written
here as binary STL, are sliced by

- PrusaSlicer for an Original Prusa MK3S (gcode_flavor marlin2, normal and
  silent mode estimates with M73 marks): once with the machine limits
  written into the file as M201-M205 (``emit_to_gcode``) and once with them
  only in the configuration block (``time_estimate_only``);
- CuraEngine with the Creality Ender-3 definition from Debian's ``cura``
  package.  The engine run alone writes a placeholder header (``;TIME:6666``,
  ``;Filament used: 0m``) and logs the real one; Cura's front end puts the
  logged header in its place, and so does this script.  The definition's
  literal ``value`` overrides (the limits among them) are passed as the front
  end would; its formula values are left to the engine's defaults.

Each file is written gzip-compressed (gcodekit reads .gcode.gz as is).
"""

from __future__ import annotations

import gzip
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
CURA = Path("/usr/share/cura/resources")

#: PrusaSlicer settings of an MK3S (0.4 mm nozzle, 0.2 mm layers, PLA): the limits are those
#: of PrusaSlicer's MK3S profile, normal mode first, silent (stealth) mode second.
PRUSA = """\
gcode_flavor = marlin2
printer_model = MK3S
printer_settings_id = Original Prusa i3 MK3S (gcodekit test)
bed_shape = 0x-4,250x-4,250x210,0x210
nozzle_diameter = 0.4
filament_diameter = 1.75
filament_density = 1.24
filament_cost = 25
layer_height = 0.2
first_layer_height = 0.2
perimeters = 2
top_solid_layers = 5
bottom_solid_layers = 4
fill_density = 15%
fill_pattern = grid
skirts = 1
retract_length = 0.8
retract_speed = 35
retract_lift = 0.4
travel_speed = 180
perimeter_speed = 45
external_perimeter_speed = 25
infill_speed = 80
solid_infill_speed = 80
top_solid_infill_speed = 40
first_layer_speed = 20
use_relative_e_distances = 1
layer_gcode = ;AFTER_LAYER_CHANGE\\n;[layer_z]\\nG92 E0
remaining_times = 1
silent_mode = 1
machine_limits_usage = {usage}
machine_max_acceleration_e = 5000,5000
machine_max_acceleration_extruding = 1250,1250
machine_max_acceleration_retracting = 1250,1250
machine_max_acceleration_travel = 1500,1250
machine_max_acceleration_x = 1000,960
machine_max_acceleration_y = 1000,960
machine_max_acceleration_z = 200,200
machine_max_feedrate_e = 120,120
machine_max_feedrate_x = 200,100
machine_max_feedrate_y = 200,100
machine_max_feedrate_z = 12,12
machine_max_jerk_e = 4.5,4.5
machine_max_jerk_x = 8,8
machine_max_jerk_y = 8,8
machine_max_jerk_z = 0.4,0.4
machine_min_extruding_rate = 0,0
machine_min_travel_rate = 0,0
start_gcode = M862.3 P "[printer_model]" ; printer model check\\nM862.1 P[nozzle_diameter] ; nozzle check\\nM115 U3.13.0 ; firmware version check\\nG90\\nM83\\nM104 S[first_layer_temperature]\\nM140 S[first_layer_bed_temperature]\\nM190 S[first_layer_bed_temperature]\\nM109 S[first_layer_temperature]\\nG28 W ; home without mesh bed levelling\\nG80 ; mesh bed levelling\\nG1 Z0.2 F720\\nG1 Y-3 F1000\\nG92 E0\\nG1 X60 E9 F1000 ; purge line\\nG1 X100 E12.5 F1000 ; purge line\\nG92 E0\\nM221 S95
end_gcode = G1 E-1 F2100\\nG1 Z30 F720\\nG1 X0 Y200 F3600\\nM104 S0\\nM140 S0\\nM107\\nM84
"""


def write_stl(path: Path, triangles: list[tuple[tuple[float, ...], ...]]) -> None:
    """A binary STL of (a, b, c) triangles, normals left to the slicer."""
    with open(path, "wb") as f:
        f.write(b"gcodekit test shape".ljust(80, b" "))
        f.write(struct.pack("<I", len(triangles)))
        for a, b, c in triangles:
            f.write(struct.pack("<12fH", 0, 0, 0, *a, *b, *c, 0))


def cube(size: float) -> list:
    corners = [(x, y, z) for x in (0, size) for y in (0, size) for z in (0, size)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    out = []
    for a, b, c, d in faces:
        out += [(corners[a], corners[b], corners[c]), (corners[a], corners[c], corners[d])]
    return out


def cylinder(radius: float, height: float, facets: int) -> list:
    ring = [(radius * math.cos(2 * math.pi * k / facets), radius * math.sin(2 * math.pi * k / facets))
            for k in range(facets)]
    out = []
    for k in range(facets):
        (x0, y0), (x1, y1) = ring[k], ring[(k + 1) % facets]
        out += [((x0, y0, 0), (x1, y1, 0), (x1, y1, height)), ((x0, y0, 0), (x1, y1, height), (x0, y0, height)),
                ((0, 0, 0), (x1, y1, 0), (x0, y0, 0)), ((0, 0, height), (x0, y0, height), (x1, y1, height))]
    return out


def gzip_to(text: bytes, target: Path) -> None:
    with gzip.GzipFile(target, "wb", mtime=0) as f:  # mtime 0: the same bytes each run
        f.write(text)


def prusa(stl: Path, usage: str, target: Path, work: Path) -> None:
    ini = work / f"prusa_{usage}.ini"
    ini.write_text(PRUSA.format(usage=usage))
    out = work / "out.gcode"
    run = subprocess.run(["prusa-slicer", "--export-gcode", "--load", str(ini), "--center", "125,105", "-o",
                          str(out), str(stl)], capture_output=True, text=True)
    if run.returncode:
        sys.exit(f"prusa-slicer failed: {run.stdout[-500:]}{run.stderr[-500:]}")
    text = out.read_bytes()
    # the banner's date changes every run: keep it out of the golden file
    text = re.sub(rb"^(; generated by PrusaSlicer \S+) on .*$", rb"\1", text, count=1, flags=re.M)
    gzip_to(text, target)


def _definition_chain(name: str) -> list[dict]:
    chain = []
    while name:
        path = CURA / "definitions" / f"{name}.def.json"
        data = json.loads(path.read_text())
        chain.append(data)
        name = data.get("inherits", "")
    return chain[::-1]


def cura_settings(printer: str) -> dict[str, str]:
    """The literal values a printer's Cura definitions set over fdmprinter's defaults."""
    settings: dict[str, str] = {}
    for data in _definition_chain(printer)[1:]:
        for key, over in data.get("overrides", {}).items():
            for field in ("default_value", "value"):
                v = over.get(field)
                if isinstance(v, bool):
                    settings[key] = "true" if v else "false"
                elif isinstance(v, (int, float)):
                    settings[key] = repr(v)
                elif field == "default_value" and isinstance(v, str) and key.endswith("_gcode"):
                    settings[key] = v.replace("{machine_depth}", str(
                        data.get("overrides", {}).get("machine_depth", {}).get("default_value", 235)))
    return settings


def cura(stl: Path, printer: str, target: Path, extra: dict[str, str]) -> None:
    out = target.with_suffix("")  # .gcode
    env = {**os.environ, "CURA_ENGINE_SEARCH_PATH": f"{CURA / 'definitions'}:{CURA / 'extruders'}"}
    args = ["CuraEngine", "slice", "-v", "-j", str(CURA / "definitions" / f"{printer}.def.json")]
    for key, value in {**cura_settings(printer), **extra}.items():
        args += ["-s", f"{key}={value}"]
    args += ["-l", str(stl), "-o", str(out)]
    log = subprocess.run(args, check=True, capture_output=True, env=env).stderr.decode("utf-8", "replace")
    header = re.search(r"^;FLAVOR:.*?(?=^End of gcode header)", log, re.S | re.M)
    if header is None:
        sys.exit("CuraEngine logged no G-code header (is it 4.x run with -v?)")
    text = out.read_text()
    out.unlink()
    placeholder = re.match(r";FLAVOR:.*?;MAXZ:[^\n]*\n", text, re.S)
    text = header[0] + text[placeholder.end():]
    gzip_to(text.encode(), target)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cube_stl, cylinder_stl = work / "cube20.stl", work / "cylinder20.stl"
        write_stl(cube_stl, cube(20.0))
        write_stl(cylinder_stl, cylinder(10.0, 10.0, 96))
        prusa(cube_stl, "emit_to_gcode", HERE / "prusa_mk3s_cube20.gcode.gz", work)
        prusa(cylinder_stl, "time_estimate_only", HERE / "prusa_mk3s_cylinder_estimate_only.gcode.gz", work)
        layers = {"layer_height": "0.2", "layer_height_0": "0.2", "infill_sparse_density": "20"}
        cura(cube_stl, "creality_ender3", HERE / "cura_ender3_cube20.gcode.gz", {**layers, "mesh_position_x": "0"})
        cura(cylinder_stl, "creality_ender3", HERE / "cura_ender3_cylinder.gcode.gz", layers)


if __name__ == "__main__":
    main()
