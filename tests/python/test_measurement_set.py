"""The measurement set as the core's class: immutable, typed columns, new sets by subset() and
with_columns(), the dict of earlier versions read the same way and converted where the core takes a set.

Data: kr500 campaigns simulated by the core (ident.simulate: nominal truth, seed 2, 0.01 mm noise) and a
probe campaign (calibration.simulation.simulate_probe, spheres with their artifact); no tolerance is at
play: every check is exact."""

from __future__ import annotations

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident
from kincal.calibration import simulation as sim


@pytest.fixture(scope="module")
def kr500():
    return kincal.load_robot("kr500")


@pytest.fixture(scope="module")
def data(kr500):
    return ident.simulate(kr500, 12, seed=2, targets=2, noise_mm=0.01)


def test_the_columns_are_typed_read_only_arrays(data):
    assert isinstance(data, kincal.MeasurementSet)
    assert len(data) == 24 and data.dof == 6 and data.n_targets == 2
    assert data.q_deg.shape == (24, 6) and data.xyz.shape == (24, 3)
    assert data.abc is None and data.setup is None and data.station_names is None  # columns it lacks
    with pytest.raises(ValueError, match="read-only"):
        data.q_deg[0, 0] = 1.0
    with pytest.raises(AttributeError):
        data.q_deg = np.zeros((24, 6))  # type: ignore[misc]
    names = data.columns()
    names["q_deg"][0, 0] += 1.0  # a copy: the set stays as it was
    assert names["q_deg"][0, 0] != data.q_deg[0, 0]


def test_subset_and_with_columns_make_new_sets(data):
    mask = np.arange(len(data)) % 3 == 0
    a = data.subset(mask)
    b = data.subset(np.flatnonzero(mask))
    assert len(a) == len(b) == int(mask.sum())
    np.testing.assert_array_equal(a.q_deg, data.q_deg[mask])
    np.testing.assert_array_equal(b.xyz, data.xyz[mask])
    assert a.source == data.source
    # only target 0 left: the set names one target
    assert data.subset(data.target == 0).n_targets == 1
    moved = data.with_columns(xyz=data.xyz + 1.0, source="moved.csv")
    np.testing.assert_array_equal(moved.xyz, data.xyz + 1.0)
    np.testing.assert_array_equal(moved.q_deg, data.q_deg)
    assert moved.source == "moved.csv" and data.source != "moved.csv"
    with pytest.raises(ValueError, match="a mask of 3 for 24 rows"):
        data.subset(np.array([True, False, True]))
    with pytest.raises(ValueError, match="row 24 of 24"):
        data.subset(np.array([0, 24]))
    with pytest.raises(ValueError, match="a boolean mask or integer indices"):
        data.subset(np.array([1.7]))
    with pytest.raises(ValueError, match="xyz of a different length|different lengths"):
        data.with_columns(xyz=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="with_columns: 'xzy' is not a column of a measurement set"):
        data.with_columns(xzy=data.xyz)


def test_a_set_from_columns_and_the_dict_of_earlier_versions(kr500, data):
    cols = data.columns()
    again = kincal.MeasurementSet(cols)
    np.testing.assert_array_equal(again.q_deg, data.q_deg)
    # read as the dict was: data["q_deg"], "abc" in data, keys, items, get
    np.testing.assert_array_equal(data["q_deg"], data.q_deg)
    assert "xyz" in data and "abc" not in data and data.get("abc") is None
    assert set(data.keys()) == set(cols) and dict(data.items()).keys() == cols.keys()
    with pytest.raises(KeyError):
        data["abc"]
    # a dict still converts wherever the core takes a set: the same errors
    e_set = _core.point_errors(kr500, np.zeros((2, 3)), data)
    e_dict = _core.point_errors(kr500, np.zeros((2, 3)), cols)
    np.testing.assert_array_equal(e_set, e_dict)
    # a set of other joints is refused where a robot reads it
    seven = kincal.MeasurementSet({**{k: v for k, v in cols.items() if k != "dir"}, "q_deg": np.zeros((24, 7)),
                                   "source": "seven.csv"})
    with pytest.raises(ValueError, match="seven.csv: 7 joint angles per row but the robot has 6"):
        _core.point_errors(kr500, np.zeros((2, 3)), seven)


def test_a_probe_set_keeps_its_stations_and_artifact(kr500):
    d = sim.simulate_probe(kr500, "sphere", stations=3, touches=8, cone_deg=35, probe=[0.0, 0.0, 150.0],
                           noise_mm=0.005, seed=1)
    assert d.station_kinds == ["sphere"] * 3 and d.artifact is not None and len(d.artifact) == 2
    first = d.subset(np.asarray(d.station) == 0)
    assert len(first) == 8 and first.station_names == d.station_names
    assert first.artifact is not None and [t[:3] for t in first.artifact] == [t[:3] for t in d.artifact]
    longer = d.with_columns(artifact=[(a, b, dist + 0.05, ang, "bar.csv:7") for a, b, dist, ang, w in d.artifact])
    assert [t[4] for t in longer.artifact] == ["bar.csv:7"] * len(d.artifact)  # where each term came from, kept
    assert [t[2] for t in longer.artifact] == pytest.approx([t[2] + 0.05 for t in d.artifact], abs=1e-12)
    with pytest.raises(ValueError, match="station"):
        d.with_columns(artifact=[("nowhere", d.station_names[0], 50.0, float("nan"), "")])
