"""URDF to kincal model: the serial revolute chain from a base link to a tip link.

Every revolute (or continuous) joint becomes a screw axis in the base frame at the zero
configuration; fixed joints fold into the next joint or the tool; inertials are kept (mass and
centre of mass) for gravity torques. URDF lengths are metres and radians; kincal's are mm and deg.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable

import numpy as np

from .._core import rotation_to_abc
from . import strict_json

if TYPE_CHECKING:
    from ..typing_ import FloatArray


def _floats(text: str | None, n: int, where: str) -> FloatArray:
    if text is None:
        return np.zeros(n)
    try:
        v = np.array([float(t) for t in text.split()], dtype=float)
    except ValueError:
        raise ValueError(f"{where}: '{text}' is not {n} numbers") from None
    if v.size != n or not np.all(np.isfinite(v)):
        raise ValueError(f"{where}: '{text}' is not {n} finite numbers")
    return v


def _rpy(r: float, p: float, y: float) -> FloatArray:
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _origin(el: ET.Element | None, where: str) -> FloatArray:
    t = np.eye(4)
    if el is not None:
        t[:3, :3] = _rpy(*_floats(el.get("rpy"), 3, where + " rpy"))
        t[:3, 3] = _floats(el.get("xyz"), 3, where + " xyz")
    return t


def _abc(r: FloatArray) -> list[float]:
    """KUKA ABC (deg) of a rotation matrix (the core's, exact at the pole)."""
    return [float(v) for v in rotation_to_abc(np.asarray(r, dtype=float))]


def _link_of(joint: ET.Element, tag: str, path: str) -> str:
    """The link named by a joint's <parent> or <child> (an error naming the joint when absent)."""
    el = joint.find(tag)
    name = el.get("link") if el is not None else None
    if not name:
        raise ValueError(f"{path}: joint '{joint.get('name')}' lacks <{tag} link=...>")
    return name


def _chain(path: str, base: str | None, tip: str | None
           ) -> tuple[ET.Element, dict[str, ET.Element], list[ET.Element], str, str]:
    """The URDF's root element, its links by name, the joints from ``base`` to ``tip`` and those two
    links' names (the only root and the only leaf below it when not named)."""
    try:
        root = ET.parse(path).getroot()
    except FileNotFoundError:
        raise ValueError(f"{path}: cannot open the URDF file") from None
    except ET.ParseError as e:
        line, col = e.position
        raise ValueError(f"{path}:{line}:{col}: not valid XML") from None
    if root.tag != "robot":
        raise ValueError(f"{path}: the root element is <{root.tag}>, not <robot>")
    links = {str(l.get("name")): l for l in root.findall("link")}
    by_child: dict[str, ET.Element] = {}
    children: dict[str, list[ET.Element]] = {}
    for j in root.findall("joint"):
        by_child[_link_of(j, "child", path)] = j
        children.setdefault(_link_of(j, "parent", path), []).append(j)
    roots = [n for n in links if n not in by_child]
    if base is None:
        if len(roots) != 1:
            raise ValueError(f"{path}: {len(roots)} root links; name the base with --base")
        base = roots[0]
    if base not in links:
        raise ValueError(f"{path}: no link '{base}'")
    if tip is None:
        # the only leaf below base
        leaves, stack = [], [base]
        while stack:
            n = stack.pop()
            kids = children.get(n, [])
            if not kids:
                leaves.append(n)
            stack.extend(_link_of(k, "child", path) for k in kids)
        if len(leaves) != 1:
            raise ValueError(f"{path}: {len(leaves)} leaf links below '{base}' ({', '.join(leaves)}); name the tip with --tip")
        tip = leaves[0]
    if tip not in links:
        raise ValueError(f"{path}: no link '{tip}'")
    chain: list[ET.Element] = []
    n = tip
    while n != base:
        up = by_child.get(n)
        if up is None:
            raise ValueError(f"{path}: link '{tip}' is not below '{base}'")
        chain.append(up)
        n = _link_of(up, "parent", path)
    chain.reverse()
    return root, links, chain, base, tip


def _limits(j: ET.Element, where: str) -> tuple[float, float, float]:
    """A revolute or continuous joint's (lower, upper, velocity) in degrees (and per second)."""
    lim = j.find("limit")
    lo, hi, vel = -180.0, 180.0, 0.0
    if lim is not None:
        if j.get("type") == "revolute":
            lo, hi = math.degrees(float(lim.get("lower", "0"))), math.degrees(float(lim.get("upper", "0")))
        vel = math.degrees(float(lim.get("velocity", "0")))
    if not lo < hi:
        raise ValueError(f"{where}: lower limit {lo:g} deg is not below upper limit {hi:g} deg")
    return lo, hi, vel


def urdf_spec(path: str | Path, base: str | None = None, tip: str | None = None) -> dict[str, Any]:
    """The kincal geometry (model JSON "nominal" section) of a URDF serial chain."""
    path = str(path)
    root, links, chain, base, tip = _chain(path, base, tip)
    t = np.eye(4)
    out_joints: list[dict[str, Any]] = []

    def inertial(link_name: str, frame: FloatArray) -> tuple[float, FloatArray]:
        el = links[link_name].find("inertial")
        if el is None:
            return 0.0, frame[:3, 3] * 1000.0
        mass_el = el.find("mass")
        m = float(mass_el.get("value", "0")) if mass_el is not None else 0.0
        c = frame @ _origin(el.find("origin"), f"{path}: link '{link_name}' inertial origin")
        return m, c[:3, 3] * 1000.0

    for j in chain:
        name, typ = j.get("name"), j.get("type")
        where = f"{path}: joint '{name}'"
        t = t @ _origin(j.find("origin"), where + " origin")
        child = _link_of(j, "child", path)
        if typ == "fixed":
            m, c = inertial(child, t)
            if out_joints and m > 0:
                # fold the mass into the previous moving link
                prev = out_joints[-1]
                tot = prev["mass_kg"] + m
                prev["com_mm"] = list((np.array(prev["com_mm"]) * prev["mass_kg"] + c * m) / tot)
                prev["mass_kg"] = tot
            continue
        if typ not in ("revolute", "continuous"):
            raise ValueError(f"{where}: type '{typ}' is not supported (a serial revolute chain is needed)")
        axis_el = j.find("axis")
        axis = _floats(axis_el.get("xyz") if axis_el is not None else "1 0 0", 3, where + " axis")
        lo, hi, vel = _limits(j, where)
        m, c = inertial(child, t)
        out_joints.append({"name": name, "point_mm": list(t[:3, 3] * 1000.0), "axis": list(t[:3, :3] @ axis),
                           "limits_deg": [lo, hi], "max_velocity_deg_s": vel, "max_acceleration_deg_s2": 0.0,
                           "max_jerk_deg_s3": 0.0, "mass_kg": m, "com_mm": list(c), "compliance_deg_per_knm": 0.0})
    if not out_joints:
        raise ValueError(f"{path}: no revolute joint between '{base}' and '{tip}'")
    return {
        "name": root.get("name", Path(path).stem),
        "joints": [{k: (list(map(float, v)) if isinstance(v, list) else v) for k, v in jt.items()} for jt in out_joints],
        "tool": {"xyz_mm": [float(x) for x in t[:3, 3] * 1000.0], "abc_deg": _abc(t[:3, :3])},
        "payload": {"mass_kg": 0.0, "com_mm": [0.0, 0.0, 0.0]},
        "gravity_m_s2": [0.0, 0.0, -9.81],
        "base_in_instrument": {"xyz_mm": [0.0, 0.0, 0.0], "abc_deg": [0.0, 0.0, 0.0]},
        "home_deg": [0.0] * len(out_joints),
    }


def urdf_model_json(path: str | Path, base: str | None = None, tip: str | None = None) -> str:
    return strict_json.dumps({"format": "kincal-model", "version": 1, "nominal": urdf_spec(path, base, tip)})


def urdf_left_out(spec: dict[str, Any]) -> list[str]:
    """Labels of the effects of a model JSON section that a URDF cannot carry (every one: URDF is
    geometry, masses and limits), e.g. ``joint_compliance(joint 2)``."""
    out = []
    for e in spec.get("effects", []):
        out.append(e["effect"] + (f"(joint {e['joint']})" if e.get("joint") else ""))
    return out


def spec_urdf(spec: dict[str, Any], name: str = "kincal_calibrated") -> str:
    """A URDF of a kincal geometry (a model JSON "nominal" or "calibrated" section).

    Every link frame keeps the base orientation at the zero configuration and sits on its joint's
    axis at the model's point of that axis (near the nominal one, so no absurd origins); each joint
    turns about its axis given in that frame. The chain's FK is then exactly the model's product of
    exponentials. The tool is a fixed joint to `tool0`; masses and centres of mass are kept."""
    def f(v: Iterable[float]) -> str:
        return " ".join(repr(float(x)) for x in v)

    out = ['<?xml version="1.0"?>', f'<robot name="{name}">']
    left = urdf_left_out(spec)
    if left:
        out.append("  <!-- kincal: URDF carries geometry only; identified effects left out: " +
                   ", ".join(left) + " (the model JSON has them) -->")
    out.append('  <link name="base_link"/>')
    prev = np.zeros(3)
    parent = "base_link"
    for i, j in enumerate(spec["joints"]):
        p = np.asarray(j["point_mm"], dtype=float)
        w = np.asarray(j["axis"], dtype=float)
        w = w / np.linalg.norm(w)
        link = f"link{i + 1}"
        lo, hi = (math.radians(v) for v in j["limits_deg"])
        vel = math.radians(j.get("max_velocity_deg_s", 0.0))
        out.append(f'  <joint name="{j["name"]}" type="revolute">')
        out.append(f'    <parent link="{parent}"/>\n    <child link="{link}"/>')
        out.append(f'    <origin xyz="{f((p - prev) / 1000.0)}" rpy="0 0 0"/>')
        out.append(f'    <axis xyz="{f(w)}"/>')
        out.append(f'    <limit lower="{lo!r}" upper="{hi!r}" effort="0" velocity="{vel!r}"/>')
        out.append('  </joint>')
        m = float(j.get("mass_kg", 0.0))
        if m > 0:
            c = (np.asarray(j["com_mm"], dtype=float) - p) / 1000.0
            out.append(f'  <link name="{link}">\n    <inertial>\n      <origin xyz="{f(c)}" rpy="0 0 0"/>\n'
                       f'      <mass value="{m!r}"/>\n'
                       f'      <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>\n    </inertial>\n  </link>')
        else:
            out.append(f'  <link name="{link}"/>')
        prev, parent = p, link
    t = np.asarray(spec["tool"]["xyz_mm"], dtype=float)
    a, b, c = (math.radians(v) for v in spec["tool"]["abc_deg"])
    out.append('  <joint name="tool_joint" type="fixed">')
    out.append(f'    <parent link="{parent}"/>\n    <child link="tool0"/>')
    out.append(f'    <origin xyz="{f((t - prev) / 1000.0)}" rpy="{f([c, b, a])}"/>')  # URDF rpy = KUKA c, b, a
    out.append('  </joint>\n  <link name="tool0"/>\n</robot>')
    return "\n".join(out) + "\n"
