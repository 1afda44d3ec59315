"""Front end (FreeCAD Path API): the legacy ``Tool`` and ``Tooltable``, and ``ToolBit`` shapes.

``Tool`` and ``Tooltable`` behave as FreeCAD 0.20's (``Path.Tool``,
``Path.Tooltable``): numbered tools, ``addTools`` numbering after the
highest, ``templateAttrs`` dictionaries.  Each tool converts to and from
:class:`gcodekit.tool_shapes.ToolShape`, the one tool-body model gcodekit's
pictures and material removal use; ``ToolBit`` is FreeCAD 0.19's newer
shape-based tool (``.fctb`` files) on the same model.

Examples
--------
>>> t1 = Tool("12.7mm Drill Bit", tooltype="Drill", diameter=12.7)
>>> t1.CuttingEdgeAngle = 118
>>> table = Tooltable()
>>> table.addTools(t1); table.addTools(Tool("my other tool", tooltype="EndMill", diameter=10))
>>> table.Tools
{1: Tool 12.7mm Drill Bit, 2: Tool my other tool}
>>> table.getTool(1).shape()
ToolShape(kind='drill', diameter=12.7, length=30.0, corner_radius=0.0, angle=118.0, tip_diameter=0.0)
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Iterable

from ..errors import ConfigError, did_you_mean
from ..tool_shapes import ToolShape

__all__ = ["Tool", "Tooltable", "ToolBit", "TOOL_TYPES", "TOOL_MATERIALS"]

#: FreeCAD 0.20's legacy tool types (``Tool.getToolTypes()``), and the gcodekit shape each is drawn as.
TOOL_TYPES: dict[str, str] = {
    "EndMill": "endmill", "Drill": "drill", "CenterDrill": "drill", "CounterSink": "chamfer",
    "CounterBore": "endmill", "FlyCutter": "endmill", "Reamer": "endmill", "Tap": "endmill",
    "SlotCutter": "endmill", "BallEndMill": "ballend", "ChamferMill": "chamfer", "CornerRound": "endmill",
    "Engraver": "vbit",
}
#: FreeCAD 0.20's tool materials (``Tool.getToolMaterials()``).
TOOL_MATERIALS = ("Carbide", "HighSpeedSteel", "HighCarbonToolSteel", "CastAlloy", "Ceramics", "Diamond", "Sialon")

#: XML attribute -> Tool field, in FreeCAD's order (its ``Tool::Save``)
XML_ATTRS = {"name": "name", "diameter": "diameter", "length": "lengthOffset", "flat": "flatRadius",
             "corner": "cornerRadius", "angle": "cuttingEdgeAngle", "height": "cuttingEdgeHeight",
             "type": "tooltype", "mat": "material"}
_ATTRS = (("name", "Name"), ("tooltype", "ToolType"), ("material", "Material"), ("diameter", "Diameter"),
          ("lengthOffset", "LengthOffset"), ("flatRadius", "FlatRadius"), ("cornerRadius", "CornerRadius"),
          ("cuttingEdgeAngle", "CuttingEdgeAngle"), ("cuttingEdgeHeight", "CuttingEdgeHeight"))


def _choice(what: str, value: str, options: Iterable[str]) -> str:
    """A tool type or material by FreeCAD's name, in any case; an unknown name is an error."""
    options = tuple(options)
    if value == "Undefined":
        return value
    for o in options:
        if o.lower() == str(value).lower():
            return o
    # FreeCAD 0.20 silently stores 'Undefined' instead
    raise ConfigError(f"unknown tool {what} {value!r}{did_you_mean(str(value), options)}; "
                      f"FreeCAD's are {', '.join(options)} or Undefined")


@dataclass(repr=False)
class Tool:
    """A legacy FreeCAD tool: name, type, material and dimensions (mm, degrees).

    Parameters are FreeCAD's keywords (``tooltype``, ``material``,
    ``diameter``, ``lengthOffset``, ``flatRadius``, ``cornerRadius``,
    ``cuttingEdgeAngle``, ``cuttingEdgeHeight``); the attributes have
    FreeCAD's capitalized names (``Diameter``, ``ToolType``, ...).

    Raises
    ------
    ConfigError
        An unknown tool type or material (FreeCAD 0.20 stores ``Undefined``
        without a word), with a did-you-mean.
    """

    name: str = "Default tool"
    tooltype: str = "Undefined"
    material: str = "Undefined"
    diameter: float = 0.0
    lengthOffset: float = 0.0  # noqa: N815 (FreeCAD's keyword)
    flatRadius: float = 0.0  # noqa: N815
    cornerRadius: float = 0.0  # noqa: N815
    cuttingEdgeAngle: float = 180.0  # noqa: N815
    cuttingEdgeHeight: float = 0.0  # noqa: N815

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise TypeError(f"argument 1 must be str, not {type(self.name).__name__}")
        self.tooltype = _choice("type", self.tooltype, TOOL_TYPES)
        self.material = _choice("material", self.material, TOOL_MATERIALS)
        for key in ("diameter", "lengthOffset", "flatRadius", "cornerRadius", "cuttingEdgeAngle", "cuttingEdgeHeight"):
            setattr(self, key, float(getattr(self, key)))

    # FreeCAD's attribute names
    Name = property(lambda self: self.name, lambda self, v: setattr(self, "name", str(v)))
    ToolType = property(lambda self: self.tooltype,
                        lambda self, v: setattr(self, "tooltype", _choice("type", v, TOOL_TYPES)))
    Material = property(lambda self: self.material,
                        lambda self, v: setattr(self, "material", _choice("material", v, TOOL_MATERIALS)))
    Diameter = property(lambda self: self.diameter, lambda self, v: setattr(self, "diameter", float(v)))
    LengthOffset = property(lambda self: self.lengthOffset, lambda self, v: setattr(self, "lengthOffset", float(v)))
    FlatRadius = property(lambda self: self.flatRadius, lambda self, v: setattr(self, "flatRadius", float(v)))
    CornerRadius = property(lambda self: self.cornerRadius, lambda self, v: setattr(self, "cornerRadius", float(v)))
    CuttingEdgeAngle = property(lambda self: self.cuttingEdgeAngle,
                                lambda self, v: setattr(self, "cuttingEdgeAngle", float(v)))
    CuttingEdgeHeight = property(lambda self: self.cuttingEdgeHeight,
                                 lambda self, v: setattr(self, "cuttingEdgeHeight", float(v)))

    def __repr__(self) -> str:
        return f"Tool {self.name}"

    def copy(self) -> "Tool":
        return Tool(**{k: getattr(self, k) for k, _ in _ATTRS})

    @property
    def Content(self) -> str:  # noqa: N802
        """The tool as FreeCAD's XML element (as ``Tool.Content`` is in FreeCAD 0.20)."""
        return ET.tostring(self._element(), encoding="unicode") + "\n"

    def _element(self) -> ET.Element:
        return ET.Element("Tool", {attr: f"{getattr(self, field):g}" if attr not in ("name", "type", "mat")
                                   else str(getattr(self, field)) for attr, field in XML_ATTRS.items()})

    @staticmethod
    def getToolTypes() -> list[str]:  # noqa: N802
        return list(TOOL_TYPES)

    @staticmethod
    def getToolMaterials() -> list[str]:  # noqa: N802
        return list(TOOL_MATERIALS)

    def templateAttrs(self) -> dict:  # noqa: N802
        """FreeCAD's dictionary of the tool (the JSON tool table's entry)."""
        return {"version": 1, **{k: getattr(self, k) for k, _ in _ATTRS}}

    def setFromTemplate(self, attrs: dict) -> None:  # noqa: N802
        """Set the fields a :meth:`templateAttrs` dictionary gives."""
        known = {k for k, _ in _ATTRS}
        for k, v in attrs.items():
            if k in known:
                setattr(self, k, v)
        self.__post_init__()

    def shape(self, *, length: float | None = None) -> ToolShape:
        """The tool's body as a :class:`~gcodekit.tool_shapes.ToolShape` (for pictures and material removal).

        End mills with a corner radius are bull noses; V-bits, drills and
        chamfer mills take the cutting edge angle (180, FreeCAD's default,
        means the kind's usual angle); a chamfer mill's flat radius is its
        tip.  Types without a shape of their own (tap, reamer, counterbore,
        slot, fly and corner-rounding cutters, Undefined) are drawn as end mills.
        """
        kind = TOOL_TYPES.get(self.tooltype, "endmill")
        if self.tooltype == "EndMill" and self.cornerRadius > 0:
            kind = "bullnose"
        angle = self.cuttingEdgeAngle if 0 < self.cuttingEdgeAngle < 180 else 0.0
        height = length if length is not None else (self.cuttingEdgeHeight or 30.0)
        return ToolShape(kind, self.diameter, height, corner_radius=self.cornerRadius if kind == "bullnose" else 0.0,
                         angle=angle if kind in ("vbit", "drill", "chamfer") else 0.0,
                         tip_diameter=2 * self.flatRadius if kind == "chamfer" else 0.0)

    @classmethod
    def from_shape(cls, shape: ToolShape, name: str = "") -> "Tool":
        """A legacy tool with the dimensions of a :class:`~gcodekit.tool_shapes.ToolShape`."""
        tooltype = {"endmill": "EndMill", "ballend": "BallEndMill", "bullnose": "EndMill", "vbit": "Engraver",
                    "drill": "Drill", "chamfer": "ChamferMill"}[shape.kind]
        return cls(name or f"{shape.diameter:g} mm {shape.kind}", tooltype=tooltype, diameter=shape.diameter,
                   cornerRadius=shape.corner_radius, flatRadius=shape.tip_diameter / 2,
                   cuttingEdgeAngle=shape.angle if shape.angle else 180.0, cuttingEdgeHeight=shape.length)


class Tooltable:
    """Tools by number: FreeCAD 0.20's ``Path.Tooltable``.

    ``Tools`` is a copy (as FreeCAD's); change the table with ``addTools``,
    ``setTool`` and ``deleteTool``.
    """

    def __init__(self, tools: "dict[int, Tool] | Iterable[Tool] | None" = None, *, name: str = ""):
        self._tools: dict[int, Tool] = {}
        self.Name = name
        self.Version = 0
        if isinstance(tools, dict):
            for number, tool in tools.items():
                self.setTool(number, tool)
        elif tools is not None:
            self.addTools(list(tools))

    @property
    def Tools(self) -> dict[int, Tool]:  # noqa: N802
        return {k: self._tools[k].copy() for k in sorted(self._tools)}

    def addTools(self, tools: "Tool | Iterable[Tool]") -> None:  # noqa: N802
        """Add a tool or a list of tools, numbered after the highest number in the table."""
        for tool in [tools] if isinstance(tools, Tool) else list(tools):
            self.setTool(max(self._tools, default=0) + 1, tool)

    def setTool(self, number: int, tool: Tool) -> None:  # noqa: N802
        """Put ``tool`` at ``number`` (replacing the tool there)."""
        if not isinstance(tool, Tool):
            raise TypeError("Argument must be a tool")
        self._tools[int(number)] = tool.copy()

    def getTool(self, number: int) -> Tool | None:  # noqa: N802
        """The tool at ``number``, or None."""
        tool = self._tools.get(int(number))
        return tool.copy() if tool is not None else None

    def deleteTool(self, number: int) -> None:  # noqa: N802
        """Remove the tool at ``number``.

        Raises
        ------
        IndexError
            ``Index not found``, as FreeCAD's.
        """
        if int(number) not in self._tools:
            raise IndexError("Index not found")
        del self._tools[int(number)]

    def templateAttrs(self) -> dict[int, dict]:  # noqa: N802
        return {k: t.templateAttrs() for k, t in sorted(self._tools.items())}

    def setFromTemplate(self, attrs: dict) -> None:  # noqa: N802
        """Replace the tools by a ``{number: templateAttrs}`` dictionary (keys may be strings, as in JSON)."""
        self._tools = {}
        for k, v in attrs.items():
            tool = Tool()
            tool.setFromTemplate(v)
            self._tools[int(k)] = tool

    @property
    def Content(self) -> str:  # noqa: N802
        """The table as FreeCAD's XML (as ``Tooltable.Content`` is in FreeCAD 0.20)."""
        root = ET.Element("Tooltable", count=str(len(self._tools)))
        for number, tool in sorted(self._tools.items()):
            ET.SubElement(root, "Toolslot", number=str(number)).append(tool._element())
        ET.indent(root, "    ")
        return ET.tostring(root, encoding="unicode") + "\n"

    def copy(self) -> "Tooltable":
        out = Tooltable(self._tools, name=self.Name)
        out.Version = self.Version
        return out

    def __len__(self) -> int:
        return len(self._tools)

    def __repr__(self) -> str:
        return f"Tooltable containing {len(self._tools)} tools"


#: ToolBit shape files (FreeCAD 0.19+) and the gcodekit shape and parameters each stands for
_BIT_SHAPES = {"endmill": "endmill", "ballend": "ballend", "bullnose": "bullnose", "v-bit": "vbit",
               "drill": "drill", "chamfer": "chamfer"}


def _quantity(value) -> float:
    """A ToolBit parameter: a number or FreeCAD's quantity text (``"5.0000 mm"``, ``"60.0000 °"``)."""
    if isinstance(value, (int, float)):
        return float(value)
    text = str(value).strip()
    number = text.split()[0] if text else ""
    try:
        return float(number.rstrip("°").replace(",", "."))
    except ValueError:
        raise ConfigError(f"ToolBit parameter {value!r} is not a number with a unit") from None


@dataclass
class ToolBit:
    """A FreeCAD 0.19+ ToolBit: a name, a shape file and its parameters (``.fctb`` JSON).

    ``shape`` is the shape file's name (``endmill.fcstd``, ``ballend.fcstd``,
    ``bullnose.fcstd``, ``v-bit.fcstd``, ``drill.fcstd``, ``chamfer.fcstd``);
    ``parameter`` holds FreeCAD's quantities (``Diameter``,
    ``CuttingEdgeHeight``, ``FlatRadius``, ``CuttingEdgeAngle``,
    ``TipAngle``, ``TipDiameter``) as numbers (mm, degrees) or as FreeCAD's
    quantity text.

    Examples
    --------
    >>> bit = ToolBit("6mm ball", "ballend.fcstd", {"Diameter": "6.0000 mm", "CuttingEdgeHeight": "20 mm"})
    >>> bit.to_shape()
    ToolShape(kind='ballend', diameter=6.0, length=20.0, corner_radius=0.0, angle=0.0, tip_diameter=0.0)
    """

    name: str
    shape: str
    parameter: dict = field(default_factory=dict)
    attribute: dict = field(default_factory=dict)

    def to_shape(self) -> ToolShape:
        """The bit's body as a :class:`~gcodekit.tool_shapes.ToolShape`."""
        stem = self.shape.rsplit("/", 1)[-1].lower().removesuffix(".fcstd")
        if stem not in _BIT_SHAPES:
            raise ConfigError(f"unknown ToolBit shape {self.shape!r}{did_you_mean(stem, _BIT_SHAPES)}")
        kind = _BIT_SHAPES[stem]
        p = {k: _quantity(v) for k, v in self.parameter.items()}
        if "Diameter" not in p:
            raise ConfigError(f"ToolBit {self.name!r} has no Diameter")
        options: dict[str, float] = {}
        if kind == "bullnose":
            options["corner_radius"] = p["Diameter"] / 2 - p.get("FlatRadius", 0.0)
        if kind in ("vbit", "chamfer"):
            options["angle"] = p.get("CuttingEdgeAngle", 0.0)
            options["tip_diameter"] = p.get("TipDiameter", 0.0) if kind == "chamfer" else 0.0
        if kind == "drill":
            options["angle"] = p.get("TipAngle", 0.0)
        if kind == "vbit" and p.get("TipDiameter", 0.0) > 0:
            kind = "chamfer"  # a V-bit with a flat tip is gcodekit's chamfer shape
            options["tip_diameter"] = p["TipDiameter"]
        return ToolShape(kind, p["Diameter"], p.get("CuttingEdgeHeight", p.get("Length", 30.0)), **options)

    @classmethod
    def from_shape(cls, shape: ToolShape, name: str = "") -> "ToolBit":
        """A ToolBit for a :class:`~gcodekit.tool_shapes.ToolShape` (FreeCAD's shape file and parameters)."""
        files = {v: k for k, v in _BIT_SHAPES.items()}
        parameter: dict[str, float] = {"Diameter": shape.diameter, "CuttingEdgeHeight": shape.length}
        if shape.kind == "bullnose":
            parameter["FlatRadius"] = shape.radius - shape.corner_radius
        if shape.kind in ("vbit", "chamfer"):
            parameter["CuttingEdgeAngle"] = shape.angle
            if shape.kind == "chamfer":
                parameter["TipDiameter"] = shape.tip_diameter
        if shape.kind == "drill":
            parameter["TipAngle"] = shape.angle
        return cls(name or f"{shape.diameter:g} mm {shape.kind}", files[shape.kind] + ".fcstd", parameter)

    def as_dict(self) -> dict:
        """The ``.fctb`` file's JSON content (version 2); lengths as FreeCAD's quantity text."""
        def text(key: str, value: float) -> str:
            unit = "°" if key.endswith("Angle") else "mm"
            return f"{value:.4f} {unit}"

        return {"version": 2, "name": self.name, "shape": self.shape,
                "parameter": {k: text(k, _quantity(v)) for k, v in self.parameter.items()},
                "attribute": dict(self.attribute)}

    @classmethod
    def from_dict(cls, data: dict) -> "ToolBit":
        """A ToolBit from a ``.fctb`` file's JSON content."""
        try:
            return cls(str(data["name"]), str(data["shape"]), dict(data.get("parameter", {})),
                       dict(data.get("attribute", {})))
        except (KeyError, TypeError, AttributeError) as exc:
            raise ConfigError(f"not a FreeCAD ToolBit: missing or bad {exc}") from None
