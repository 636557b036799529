"""The F distribution's survival function for the significance rule of the effect choice
(stepwise.score), in plain Python: scipy.special costs a quarter of a second to import, as much as
the linear scores of a whole choice, and every `kincal identify` needs one p-value per candidate.

P(F > f) for F ~ F(d1, d2) is the regularised incomplete beta function I_x(d2/2, d1/2) at
x = d2 / (d2 + d1 f), evaluated by its continued fraction (modified Lentz), on the side of the
symmetry I_x(a, b) = 1 - I_{1-x}(b, a) where the fraction converges fast (tests/python: against
scipy.special.fdtrc)."""

from __future__ import annotations

import math

_TINY = 1e-300
_EPS = 1e-15


def _fraction(a: float, b: float, x: float) -> float:
    """The continued fraction of I_x(a, b) (for x < (a + 1) / (a + b + 2))."""
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > _TINY else _TINY)
    h = d
    for m in range(1, 100000):
        m2 = 2 * m
        for num in (m * (b - m) * x / ((a + m2 - 1.0) * (a + m2)),
                    -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0))):
            d = 1.0 + num * d
            d = 1.0 / (d if abs(d) > _TINY else _TINY)
            c = 1.0 + num / c
            c = c if abs(c) > _TINY else _TINY
            h *= d * c
        if abs(d * c - 1.0) < _EPS:
            return h
    raise ArithmeticError(f"the incomplete beta function's fraction did not converge (a={a}, b={b}, x={x})")


def incomplete_beta(a: float, b: float, x: float) -> float:
    """The regularised incomplete beta function I_x(a, b), a, b > 0."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    front = math.exp(math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x))
    if x < (a + 1.0) / (a + b + 2.0):
        return front * _fraction(a, b, x) / a
    return 1.0 - front * _fraction(b, a, 1.0 - x) / b


def f_survival(d1: float, d2: float, f: float) -> float:
    """P(F > f) for F ~ F(d1, d2) (scipy.special.fdtrc(d1, d2, f))."""
    if d1 <= 0 or d2 <= 0:
        raise ValueError(f"the F distribution's degrees of freedom must be positive, not {d1}, {d2}")
    if f <= 0:
        return 1.0
    if math.isinf(f):
        return 0.0
    return incomplete_beta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f))
