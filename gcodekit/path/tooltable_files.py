"""Front end (FreeCAD Path API): tool tables in FreeCAD's JSON and XML files and LinuxCNC's ``.tbl``.

* JSON: FreeCAD's legacy tool library, ``{"TableName": ..., "Version": 1,
  "Tools": {"1": {templateAttrs}, ...}}``; a list of such tables (FreeCAD
  0.18 saves several in one file) or a bare ``{"1": {...}}`` is read too.
* XML: FreeCAD's ``Tooltable.Content``, ``<Tooltable><Toolslot
  number="1"><Tool name=... diameter=... type=... mat=.../></Toolslot>``.
* ``.tbl``: LinuxCNC's tool table, read by
  :class:`gcodekit.emulate.tooltable.ToolTable`; the comment is the name,
  ``D`` the diameter and ``Z`` the length offset.

Examples
--------
>>> from gcodekit.path.tools import Tool, Tooltable
>>> table = Tooltable([Tool("3 mm end mill", tooltype="EndMill", diameter=3, lengthOffset=40)])
>>> print(tooltable_to_tbl(table), end="")
T1 P1 D3.000000 Z40.000000 ;3 mm end mill
>>> tooltable_from_text(tooltable_to_json(table), "json").getTool(1).Diameter
3.0
"""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as ET

from ..emulate.tooltable import ToolTable
from ..errors import ConfigError
from .tools import XML_ATTRS, Tool, Tooltable

__all__ = ["read_tooltable", "write_tooltable", "tooltable_from_text", "tooltable_to_json", "tooltable_to_xml",
           "tooltable_to_tbl"]

_FORMATS = {".json": "json", ".xml": "xml", ".tbl": "tbl"}


def tooltable_from_text(text: str, fmt: str, *, units: str = "mm", source: str = "<tool table>") -> Tooltable:
    """A tool table from the text of a ``json``, ``xml`` or ``tbl`` file.

    ``units`` applies to ``.tbl`` files only (LinuxCNC writes them in the
    machine's units).

    Raises
    ------
    ConfigError
        Text that is not a tool table of that format, naming the source.
    """
    if fmt == "json":
        return _from_json(text, source)
    if fmt == "xml":
        return _from_xml(text, source)
    if fmt == "tbl":
        table = Tooltable(name=os.path.basename(source))
        for number, entry in sorted(ToolTable.parse(text, units=units, source=source).items()):
            table.setTool(number, Tool(entry.comment or f"T{number}", diameter=entry.diameter,
                                       lengthOffset=float(entry.offset[2])))
        return table
    raise ConfigError(f"unknown tool table format {fmt!r}: json, xml or tbl")


def _from_json(text: str, source: str) -> Tooltable:
    try:
        data = json.loads(text)
    except ValueError as exc:
        raise ConfigError(f"{source}: not JSON: {exc}") from None
    if isinstance(data, list):  # FreeCAD 0.18: several tables in one file; the first is read
        if not data:
            raise ConfigError(f"{source}: an empty list of tool tables")
        data = data[0]
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: a tool table is a JSON object, not {type(data).__name__}")
    tools = data.get("Tools", data)
    table = Tooltable(name=str(data.get("TableName", "")))
    table.Version = int(data.get("Version", 1))
    try:
        table.setFromTemplate({k: v for k, v in tools.items() if str(k).isdigit()})
    except (TypeError, ValueError, AttributeError) as exc:
        raise ConfigError(f"{source}: a tool entry is not a FreeCAD tool: {exc}") from None
    return table


def _from_xml(text: str, source: str) -> Tooltable:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ConfigError(f"{source}: not XML: {exc}") from None
    if root.tag != "Tooltable":
        raise ConfigError(f"{source}: the root element is <{root.tag}>, not <Tooltable>")
    table = Tooltable()
    for slot in root.iter("Toolslot"):
        element = slot.find("Tool")
        if element is None or "number" not in slot.attrib:
            raise ConfigError(f"{source}: a <Toolslot> without a number or a <Tool>")
        values = {field: element.attrib[attr] for attr, field in XML_ATTRS.items() if attr in element.attrib}
        for key in ("diameter", "lengthOffset", "flatRadius", "cornerRadius", "cuttingEdgeAngle", "cuttingEdgeHeight"):
            if key in values:
                try:
                    values[key] = float(values[key])
                except ValueError:
                    raise ConfigError(f"{source}: tool {slot.attrib['number']}: {key} {values[key]!r} is not a number")
        table.setTool(int(slot.attrib["number"]), Tool(**values))
    return table


def tooltable_to_json(table: Tooltable) -> str:
    """FreeCAD's JSON tool library text for the table."""
    data = {"TableName": table.Name, "Version": 1,
            "Tools": {str(k): v for k, v in table.templateAttrs().items()}}
    return json.dumps(data, indent=2) + "\n"


def tooltable_to_xml(table: Tooltable) -> str:
    """FreeCAD's XML text for the table (``Tooltable.Content``)."""
    return table.Content


def tooltable_to_tbl(table: Tooltable) -> str:
    """LinuxCNC's tool table text (mm): ``T<n> P<n> D<diameter> Z<length offset> ;<name>``."""
    lines = [f"T{n} P{n} D{tool.Diameter:.6f} Z{tool.LengthOffset:.6f} ;{' '.join(tool.Name.split())}"
             for n, tool in table.Tools.items()]
    return "".join(line + "\n" for line in lines)


def read_tooltable(path: str | os.PathLike, *, units: str = "mm") -> Tooltable:
    """Read a tool table file; the format comes from the extension (``.json``, ``.xml``, ``.tbl``)."""
    fmt = _FORMATS.get(os.path.splitext(os.fspath(path))[1].lower())
    if fmt is None:
        raise ConfigError(f"{os.fspath(path)!r}: a tool table file ends in .json, .xml or .tbl")
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
    except OSError as exc:
        raise ConfigError(f"cannot read tool table {os.fspath(path)!r}: {exc}") from exc
    return tooltable_from_text(text, fmt, units=units, source=os.fspath(path))


def write_tooltable(table: Tooltable, path: str | os.PathLike) -> None:
    """Write a tool table file in the format of its extension (``.json``, ``.xml``, ``.tbl``)."""
    fmt = _FORMATS.get(os.path.splitext(os.fspath(path))[1].lower())
    writers = {"json": tooltable_to_json, "xml": tooltable_to_xml, "tbl": tooltable_to_tbl}
    if fmt is None:
        raise ConfigError(f"{os.fspath(path)!r}: a tool table file ends in .json, .xml or .tbl")
    with open(path, "w", encoding="utf-8") as f:
        f.write(writers[fmt](table))
