"""Where identification's gravity torques come from, for the summary and the model JSON.

Joint compliance deflects a joint by compliance x gravity torque. With the model's mass table
(``--gravity masses``, the default ``auto`` when any link has a mass) the torques come from the link
masses and centres of mass, as before. Without one (``--gravity fit``, or ``auto`` on a model with no
inertial data, e.g. a URDF without <inertial> tags) each link's first moment across its joint's axis
is identified with the compliances (the core's point_model.hpp says why that form): the points see
only compliance x moment, so one compliance is held as the scale and the written model's link masses
(1 kg each) and centres of mass are effective values that reproduce the identified deflection in
``fk``, ``compensate`` and ``kincal-compensate``, not the robot's real masses.
"""

from __future__ import annotations

from typing import Any

from .. import _core

MODES = ("auto", "masses", "fit")


def _held_scale(fit: _core.IdentifyResult) -> dict[str, Any] | None:
    """The compliance held as the scale of the fitted moments (name, value), if one is."""
    for p, x, fx, why in zip(fit.layout.parameters, fit.x, fit.fixed, fit.fixed_reason):
        if p.kind == "compliance" and fx and why.startswith("the scale of the fitted mass moments"):
            return {"parameter": p.name, "value": float(x), "unit": p.unit}
    return None


def report(fit: _core.IdentifyResult) -> dict[str, Any]:
    """The model JSON's ``identification.gravity``: the source of the gravity torques and, when fitted,
    the held scale and what the written masses mean."""
    if fit.layout.gravity != "fit":
        return {"source": "masses", "text": "the model's link masses and centres of mass"}
    out: dict[str, Any] = {"source": "fit",
                 "text": "no mass table: each link's first moment across its joint's axis identified with the "
                         "compliances (compliance x moment is what the points see)",
                 "link_masses": "effective (1 kg per fitted link, centre of mass placed to give the identified "
                                "torques); the compliances are relative to the held one; a different payload "
                                "would not be scaled right unless the data carried several payloads"}
    held = _held_scale(fit)
    if held:
        out["held_scale"] = held
    return out


def summary_line(fit: _core.IdentifyResult) -> str:
    """One line of the identify summary saying where the gravity torques came from."""
    if fit.layout.gravity != "fit":
        return "gravity torques of the compliances: from the model's link masses (--gravity masses)"
    held = _held_scale(fit)
    scale = (f"; {held['parameter']} held at {held['value']:.4g} {held['unit']} as their scale, the other "
             f"compliances relative to it" if held else "; their scale from the data's payloads")
    return ("gravity torques of the compliances: no link masses in the model, mass moments identified "
            f"(--gravity fit: link*.moment_u/v, effective 1 kg links in the written model){scale}")
