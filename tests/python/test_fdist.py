"""The F distribution's survival function of the effect choice's significance rule (kincal.fdist, plain
Python) against scipy.special.fdtrc: degrees of freedom 1..100 (the candidates' columns) by 1..200000
(residual coordinates of a campaign), F from 0 to 1e7."""

from __future__ import annotations

import math

import pytest

from kincal.stats.fdist import f_survival, incomplete_beta


def test_f_survival_agrees_with_scipy():
    from scipy.special import fdtrc

    for d1 in (1, 2, 3, 5, 8, 16, 48, 100):
        for d2 in (1, 2, 5, 10, 50, 300, 1600, 35000, 200000):
            for f in (0.0, 1e-6, 0.01, 0.3, 0.9, 1.0, 1.1, 2.0, 3.5, 10.0, 50.0, 1e3, 1.8e4, 1e7):
                want, got = float(fdtrc(d1, d2, f)), f_survival(d1, d2, f)
                if want > 1e-200:  # beyond, scipy's own error grows (the exact sum below)
                    assert got == pytest.approx(want, rel=1e-8), (d1, d2, f)
                else:
                    assert got < 1e-190, (d1, d2, f)


def test_far_tail_against_the_exact_sum():
    """I_x(a, b) for integers a, b is a binomial tail: summed in exact fractions at F(48, 1600) = 50
    (p about 1e-279; scipy's fdtrc gives 1.59e-279 there, 38% off)."""
    from fractions import Fraction

    a, b, x = 800, 24, Fraction(1600, 1600 + 48 * 50)
    n = a + b - 1
    exact = float(sum(math.comb(n, j) * x ** j * (1 - x) ** (n - j) for j in range(a, n + 1)))
    assert f_survival(48, 1600, 50.0) == pytest.approx(exact, rel=1e-9)


def test_edges_and_symmetry():
    assert f_survival(3, 10, 0.0) == 1.0 and f_survival(3, 10, math.inf) == 0.0
    assert incomplete_beta(2.5, 4.0, 0.3) == pytest.approx(1.0 - incomplete_beta(4.0, 2.5, 0.7), rel=1e-13)
    assert incomplete_beta(1.0, 1.0, 0.37) == pytest.approx(0.37, rel=1e-14)  # the uniform distribution
    with pytest.raises(ValueError, match="degrees of freedom"):
        f_survival(0, 10, 1.0)
