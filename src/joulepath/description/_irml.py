"""IRML, the thesis' XML robot description (thesis §2.1 and Appendix C): reader and writer.

Layout (our version 0.2 adds the optional ``<limits>``, ``<range-set>``,
``<base>`` and ``<payload>`` blocks to the thesis' 0.1)::

    <robot>
      <name>IRB 120</name> <manufacturer>ABB</manufacturer> ... general information
      <joint id="1">
        <type>T</type> <xi>1</xi>                      T/R revolute (xi 1), L linear (xi 0)
        <kinematics> <q>q1</q> <d>0.29</d> <r>0</r> <a>-pi/2</a> </kinematics>
        <dynamics> <link-mass>3.067</link-mass>
          <center><x/><y/><z/></center>  <inertia><xx/><xy/>...<zz/></inertia> </dynamics>
        <limits> <lower/> <upper/> <velocity/> <effort/> </limits>   (rad, rad/s, N·m)
      </joint>
      <range-set name="lab"> <joint id="1"><lower/><upper/></joint> ... </range-set>
      <payload> <link-mass/> <center/> <inertia/> </payload>       (at tool0)
    </robot>

Numbers may be arithmetic expressions (``-pi/2``, ``165*pi/180``); ``<q>`` is the
joint variable with an optional sign and offset (``q2 - pi/2``). Expressions are
evaluated by :mod:`joulepath.description._expr`, never by ``eval``. The XML is
parsed with defusedxml: entity expansion and external references are refused.
Frame conventions: see :mod:`joulepath.description._model`.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml
import defusedxml.ElementTree as DET

from joulepath._io import atomic_write_text
from joulepath.description._expr import (
    ExpressionError,
    evaluate,
    evaluate_affine,
    format_angle,
    format_number,
)
from joulepath.description._model import (
    JOINT_TYPES,
    Inertial,
    JointDescription,
    RangeSet,
    RobotDescription,
)
from joulepath.errors import InvalidRobotDescription

_STRUCTURAL = {"joint", "range-set", "payload", "base", "name", "manufacturer"}
_INERTIA_TAGS = ("xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz")
IRML_VERSION = "0.2"
MAX_BYTES = 4 << 20
"""Largest IRML file read (4 MiB); a robot description is a few kB."""
MAX_DEPTH = 16
"""Deepest nesting of general-information elements (``<loads><maximal-loads><fx>`` is 3)."""
MAX_JOINTS = 64
_ID = re.compile(r"[0-9]{1,6}")


class _Ctx:
    """Where we are in the file, for error messages."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, problem: str, fix: str = "") -> InvalidRobotDescription:
        msg = f"{self.source}: {where}: {problem}"
        if fix:
            msg += f"; {fix}"
        return InvalidRobotDescription(msg)


def _short(text: str, n: int = 40) -> str:
    """``repr`` of ``text`` cut to about ``n`` characters, for messages."""
    return repr(text if len(text) <= n else text[:n] + "…")


def _joint_id(raw: str | None) -> int | None:
    """The integer of a joint id attribute (decimal digits only), else None."""
    text = (raw or "").strip()
    return int(text) if _ID.fullmatch(text) else None


def _children(el: ET.Element, tag: str) -> list[ET.Element]:
    return [c for c in el if c.tag == tag]


def _child(el: ET.Element, tag: str, ctx: _Ctx, where: str) -> ET.Element:
    found = _children(el, tag)
    if not found:
        raise ctx.fail(where, f"missing <{tag}>", f"add a <{tag}> element inside <{el.tag}>")
    if len(found) > 1:
        raise ctx.fail(where, f"<{tag}> appears {len(found)} times", "keep exactly one")
    return found[0]


def _text(el: ET.Element, ctx: _Ctx, where: str) -> str:
    text = (el.text or "").strip()
    if not text:
        raise ctx.fail(f"{where} <{el.tag}>", "is empty", "write a value")
    return text


def _number(el: ET.Element, tag: str, ctx: _Ctx, where: str) -> float:
    child = _child(el, tag, ctx, where)
    text = _text(child, ctx, where)
    try:
        return evaluate(text)
    except ExpressionError as err:
        raise ctx.fail(
            f"{where} <{tag}>",
            f"{_short(text)} {err}",
            "write a number or an expression such as 0.29 or -pi/2",
        ) from err


def _optional_number(el: ET.Element, tag: str, ctx: _Ctx, where: str) -> float | None:
    if not _children(el, tag):
        return None
    return _number(el, tag, ctx, where)


def _inertial(el: ET.Element, ctx: _Ctx, where: str) -> Inertial:
    mass = _number(el, "link-mass", ctx, where)
    center = _child(el, "center", ctx, where)
    com = tuple(_number(center, t, ctx, f"{where} <center>") for t in ("x", "y", "z"))
    inertia_el = _child(el, "inertia", ctx, where)
    vals = [_number(inertia_el, t, ctx, f"{where} <inertia>") for t in _INERTIA_TAGS]
    return Inertial.from_arrays(mass, com, [vals[0:3], vals[3:6], vals[6:9]])


def _joint(el: ET.Element, ctx: _Ctx) -> JointDescription:
    raw_id = el.get("id")
    if raw_id is None:
        raise ctx.fail("<joint>", "has no id attribute", 'write <joint id="1">')
    jid = _joint_id(raw_id)
    if jid is None:
        raise ctx.fail(
            f"joint {_short(raw_id)}", "id is not an integer (of at most 6 digits)", 'write <joint id="1">'
        )
    where = f"joint {jid}"
    jtype = _text(_child(el, "type", ctx, where), ctx, where)
    if jtype not in JOINT_TYPES:
        raise ctx.fail(
            f"{where} <type>",
            f"unknown joint type {_short(jtype)}",
            "use T (torsion), R (rotational) or L (linear)",
        )
    if jtype == "L":
        raise ctx.fail(
            f"{where} <type>",
            "linear (prismatic) joints are not supported by joulepath's kinematics",
            "describe a robot with revolute joints (T or R)",
        )
    xi_text = _text(_child(el, "xi", ctx, where), ctx, where)
    if xi_text not in ("0", "1"):
        raise ctx.fail(f"{where} <xi>", f"{_short(xi_text)} is not 0 or 1", "write 1 for T/R joints")
    xi = int(xi_text)
    if xi != 1:
        raise ctx.fail(f"{where} <xi>", f"xi is 0 but the type is {jtype}", "write <xi>1</xi>")
    kin = _child(el, "kinematics", ctx, where)
    q_el = _child(kin, "q", ctx, f"{where} <kinematics>")
    q_text = _text(q_el, ctx, f"{where} <kinematics>")
    variable = f"q{jid}"
    try:
        aff = evaluate_affine(q_text, frozenset({variable}))
    except ExpressionError as err:
        raise ctx.fail(
            f"{where} <kinematics> <q>",
            f"{_short(q_text)} {err}",
            f"write the joint variable, e.g. {variable} or {variable} - pi/2",
        ) from err
    if aff.var != variable or aff.coef not in (1.0, -1.0):
        raise ctx.fail(
            f"{where} <kinematics> <q>",
            f"{_short(q_text)} is not ±{variable} plus a constant offset",
            f"write e.g. {variable} or {variable} - pi/2",
        )
    kw = f"{where} <kinematics>"
    dyn = _child(el, "dynamics", ctx, where)
    lim = _children(el, "limits")
    limits: dict[str, float | None] = {
        "lower": None,
        "upper": None,
        "velocity": None,
        "effort": None,
    }
    if lim:
        for key in limits:
            limits[key] = _optional_number(lim[0], key, ctx, f"{where} <limits>")
    return JointDescription(
        id=jid,
        type=jtype,
        xi=xi,
        variable=variable,
        sign=aff.coef,
        offset=aff.const,
        d=_number(kin, "d", ctx, kw),
        r=_number(kin, "r", ctx, kw),
        alpha=_number(kin, "a", ctx, kw),
        inertial=_inertial(dyn, ctx, f"{where} <dynamics>"),
        **limits,
    )


def _flatten_info(root: ET.Element, ctx: _Ctx) -> list[tuple[str, str]]:
    """General information as ``(path, text)`` in document order; refuses nesting past MAX_DEPTH."""
    out: list[tuple[str, str]] = []
    stack: list[tuple[ET.Element, str, int]] = [(root, "", 0)]
    while stack:
        el, prefix, depth = stack.pop()
        items: list[tuple[ET.Element, str, int]] = []
        for child in el:
            if not isinstance(child.tag, str):  # comments, processing instructions
                continue
            if prefix == "" and child.tag in _STRUCTURAL:
                continue
            path = f"{prefix}{child.tag}"
            if len(child):
                if depth + 1 >= MAX_DEPTH:
                    raise ctx.fail(
                        f"<{path.split('/')[0]}>",
                        f"general information is nested deeper than {MAX_DEPTH} levels",
                        "flatten it",
                    )
                items.append((child, path + "/", depth + 1))
            else:
                items.append((child, path, -1))
        # depth-first, in document order: leaves are emitted when popped
        for item in reversed(items):
            stack.append(item)
        while stack and stack[-1][2] == -1:
            leaf, path, _ = stack.pop()
            out.append((path, (leaf.text or "").strip()))
    return out


def _range_set(el: ET.Element, joint_ids: list[int], ctx: _Ctx) -> RangeSet:
    name = el.get("name")
    if not name:
        raise ctx.fail("<range-set>", "has no name attribute", 'write <range-set name="lab">')
    where = f"range-set {name!r}"
    by_id: dict[int, tuple[float, float]] = {}
    for j in _children(el, "joint"):
        jid = _joint_id(j.get("id"))
        if jid is None:
            raise ctx.fail(where, "a <joint> has no integer id", 'write <joint id="1">')
        lo = _number(j, "lower", ctx, f"{where} joint {jid}")
        hi = _number(j, "upper", ctx, f"{where} joint {jid}")
        by_id[jid] = (lo, hi)
    missing = [i for i in joint_ids if i not in by_id]
    if missing:
        raise ctx.fail(where, f"has no range for joint(s) {missing}", "give every joint a range")
    return RangeSet(
        name=name,
        lower=tuple(by_id[i][0] for i in joint_ids),
        upper=tuple(by_id[i][1] for i in joint_ids),
    )


def parse_irml(data: str | bytes, *, source: str = "<string>") -> RobotDescription:
    """Parse IRML text into a :class:`RobotDescription`.

    Raises
    ------
    InvalidRobotDescription
        Malformed XML, forbidden entities or DTDs, a missing or invalid field. The
        message names the source, the joint id and the tag.
    """
    ctx = _Ctx(source)
    if len(data) > MAX_BYTES:
        raise ctx.fail("file", f"is larger than {MAX_BYTES >> 20} MiB", "an IRML file is a few kB")
    try:
        root = DET.fromstring(data, forbid_dtd=True)
    except defusedxml.DefusedXmlException as err:
        raise ctx.fail(
            "XML",
            f"refused ({type(err).__name__}): entities and DTDs are not allowed in IRML",
            "remove the <!DOCTYPE>/<!ENTITY> declarations",
        ) from err
    except ET.ParseError as err:
        line, col = err.position
        raise ctx.fail(f"line {line}, column {col}", f"not well-formed XML ({err})") from err
    except (LookupError, ValueError) as err:  # unknown encoding declared, text that is not XML
        raise ctx.fail("XML", f"cannot be decoded ({err})", "save the file as UTF-8") from err
    if root.tag != "robot":
        raise ctx.fail("root", f"the root element is <{str(root.tag)[:40]}>", "IRML files start with <robot>")
    name = _text(_child(root, "name", ctx, "robot"), ctx, "robot")
    manu = _children(root, "manufacturer")
    manufacturer = (manu[0].text or "").strip() if manu else ""
    seen: set[str] = set()
    joint_els = _children(root, "joint")
    if len(joint_els) > MAX_JOINTS:
        raise ctx.fail(
            "robot", f"has {len(joint_els)} joints; at most {MAX_JOINTS} are supported", "describe an arm"
        )
    for el in joint_els:
        jid = _joint_id(el.get("id"))
        raw = str(jid) if jid is not None else (el.get("id") or "").strip()
        if raw and raw in seen:
            shown = raw if jid is not None else _short(raw)
            raise ctx.fail(f"joint {shown}", "duplicate joint id", "give each joint its own id")
        seen.add(raw)
    joints = [_joint(el, ctx) for el in joint_els]
    if not joints:
        raise ctx.fail("robot", "has no <joint>", "describe at least one joint")
    info = _flatten_info(root, ctx)
    for key in ("manipulator-mass", "reach", "carrying-capacity"):
        for k, v in info:
            if k == key:
                try:
                    ok = math.isfinite(float(v))
                except ValueError:
                    ok = False
                if not ok:
                    raise ctx.fail(f"<{key}>", f"{_short(v)} is not a finite number", "write e.g. 25")
    ids = [j.id for j in joints]
    base = _children(root, "base")
    payload = _children(root, "payload")
    return RobotDescription(
        name=name,
        manufacturer=manufacturer,
        info=tuple(info),
        joints=tuple(joints),
        base=_inertial(base[0], ctx, "<base>") if base else None,
        payload=_inertial(payload[0], ctx, "<payload>") if payload else None,
        range_sets=tuple(_range_set(el, ids, ctx) for el in _children(root, "range-set")),
        source=source,
    )


def read_irml(path: str | os.PathLike[str]) -> RobotDescription:
    """Read an IRML file.

    Raises
    ------
    InvalidRobotDescription
        See :func:`parse_irml`; also when the file cannot be read.
    """
    p = Path(path)
    try:
        if p.exists() and not p.is_file():
            what = "is a folder" if p.is_dir() else "is not a regular file"
            raise InvalidRobotDescription(f"{p}: {what}; give the path of an .irml file")
        if p.exists() and p.stat().st_size > MAX_BYTES:
            raise InvalidRobotDescription(
                f"{p}: is larger than {MAX_BYTES >> 20} MiB; an IRML file is a few kB"
            )
        data = p.read_bytes()
    except OSError as err:
        raise InvalidRobotDescription(f"{p}: cannot be read ({err.strerror})") from err
    return parse_irml(data, source=str(p))


def _sub(parent: ET.Element, tag: str, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, tag)
    if text is not None:
        el.text = text
    return el


def _write_inertial(parent: ET.Element, inertial: Inertial) -> None:
    _sub(parent, "link-mass", format_number(inertial.mass))
    center = _sub(parent, "center")
    for tag, v in zip(("x", "y", "z"), inertial.com, strict=True):
        _sub(center, tag, format_number(v))
    inertia = _sub(parent, "inertia")
    flat = [v for row in inertial.inertia for v in row]
    for tag, v in zip(_INERTIA_TAGS, flat, strict=True):
        _sub(inertia, tag, format_number(v))


def _q_text(j: JointDescription) -> str:
    text = ("-" if j.sign < 0 else "") + j.variable
    if j.offset != 0.0:
        off = format_angle(j.offset)
        text += f" - {off[1:]}" if off.startswith("-") else f" + {off}"
    return text


def irml_string(desc: RobotDescription) -> str:
    """Serialize a description to IRML text; :func:`parse_irml` reads it back identically."""
    root = ET.Element("robot", {"irml-version": IRML_VERSION})
    _sub(root, "name", desc.name)
    if desc.manufacturer:
        _sub(root, "manufacturer", desc.manufacturer)
    groups: dict[str, ET.Element] = {}
    for path, text in desc.info:
        parts = path.split("/")
        parent = root
        for depth in range(1, len(parts)):
            key = "/".join(parts[:depth])
            if key not in groups:
                groups[key] = _sub(parent, parts[depth - 1])
            parent = groups[key]
        _sub(parent, parts[-1], text)
    if desc.base is not None:
        _write_inertial(_sub(root, "base"), desc.base)
    for j in desc.joints:
        el = _sub(root, "joint")
        el.set("id", str(j.id))
        _sub(el, "type", j.type)
        _sub(el, "xi", str(j.xi))
        kin = _sub(el, "kinematics")
        _sub(kin, "q", _q_text(j))
        _sub(kin, "d", format_number(j.d))
        _sub(kin, "r", format_number(j.r))
        _sub(kin, "a", format_angle(j.alpha))
        _write_inertial(_sub(el, "dynamics"), j.inertial)
        limits = {"lower": j.lower, "upper": j.upper, "velocity": j.velocity, "effort": j.effort}
        if any(v is not None for v in limits.values()):
            lim = _sub(el, "limits")
            for tag, v in limits.items():
                if v is not None:
                    fmt = format_angle if tag in ("lower", "upper") else format_number
                    _sub(lim, tag, fmt(v))
    for rs in desc.range_sets:
        el = _sub(root, "range-set")
        el.set("name", rs.name)
        for j, lo, hi in zip(desc.joints, rs.lower, rs.upper, strict=True):
            je = _sub(el, "joint")
            je.set("id", str(j.id))
            _sub(je, "lower", format_angle(lo))
            _sub(je, "upper", format_angle(hi))
    if desc.payload is not None:
        _write_inertial(_sub(root, "payload"), desc.payload)
    ET.indent(root, space="  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write_irml(desc: RobotDescription, path: str | os.PathLike[str]) -> Path:
    """Write IRML atomically (temporary file, then rename) and return the path."""
    return atomic_write_text(path, irml_string(desc))
