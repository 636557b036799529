"""Grouped validation: repeats of one configuration never sit on both sides of a split or a fold.

Simulated campaign (kr500, default_truth(seed 3): geometric errors and compliance): 36 random
configurations, each measured 8 times with fresh Gaussian noise of 0.02 mm per coordinate, and a
transmission error of joint 2 (amplitudes 0.017/0.011/0.009/0.006 deg) that the identified model
(geometry + compliance) does not carry: the effect outside the model that row-wise folds hide.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.stats import grouping
from kincal.calibration import identify as ident

from conftest import run

CONFIGS, REPEATS, NOISE = 36, 8, 0.02


def _repeated(config_column: bool = False, seeds: tuple[int, int, int] = (3, 4, 7)) -> tuple[dict, np.ndarray]:
    """The campaign; ``seeds``: the truth's, the configurations', the repeats' noise."""
    robot = kincal.load_robot("kr500")
    truth = ident.default_truth(robot, seed=seeds[0])
    base = ident.simulate(truth, CONFIGS, seed=seeds[1], noise_mm=0.0,
                          effects=[("transmission_error", 2, [3e-4, -2e-4, 1.5e-4, 1e-4])])
    rng = np.random.default_rng(seeds[2])
    reps = []
    for r in range(REPEATS):
        d = base.columns()  # writable copies
        d["pose"] = d["pose"] + 1000 * r          # a new pose id for every repeat
        d["xyz"] = d["xyz"] + rng.normal(0.0, NOISE, d["xyz"].shape)
        reps.append(d)
    data = {k: (np.concatenate([d[k] for d in reps]) if isinstance(v, np.ndarray) else v) for k, v in base.items()}
    truth_config = data["pose"] % 1000
    if config_column:
        # the controller reports slightly different angles for each repeat (0.01 deg, beyond the
        # equal-angle rule): only the config column says they repeat one configuration
        data["q_deg"] = data["q_deg"] + rng.normal(0.0, 0.01, data["q_deg"].shape)
        data["config"] = truth_config.astype(np.int64)
    return kincal.MeasurementSet(data), truth_config


@pytest.fixture(scope="module")
def repeated():
    return _repeated()


def _held_rms(robot, data, effects, held_masks) -> float:
    sq = []
    for held in held_masks:
        r = _core.identify(robot, ident.subset(data, ~held), ident.options(effects, covariance=False))
        sq.append(_core.point_errors(r.robot, r.targets, ident.subset(data, held)) ** 2)
    return float(np.sqrt(np.mean(np.concatenate(sq))))


def test_configurations_found_from_equal_joint_angles(repeated):
    data, truth_config = repeated
    cfg = grouping.configurations(data)
    assert cfg.count == CONFIGS
    # the groups are exactly the simulated configurations (one code per configuration)
    pairs = set(zip(cfg.codes.tolist(), truth_config.tolist()))
    assert len(pairs) == CONFIGS


def test_folds_and_split_keep_configurations_whole(repeated):
    data, truth_config = repeated
    masks = grouping.folds(data, 4, seed=1)
    assert np.array_equal(np.sum(masks, axis=0), np.ones(len(truth_config)))   # a partition
    for held in masks:
        assert not set(truth_config[held]) & set(truth_config[~held])
    fit, held = grouping.split(data, 0.25, seed=2)
    assert held.sum() == 9 * REPEATS and not set(truth_config[held]) & set(truth_config[fit])


def test_config_column_groups_jittered_repeats():
    data, truth_config = _repeated(config_column=True)
    assert grouping.configurations(kincal.MeasurementSet({k: v for k, v in data.items() if k != "config"})).count == CONFIGS * REPEATS
    cfg = grouping.configurations(data)
    assert cfg.count == CONFIGS and "config" in cfg.rule
    for held in grouping.folds(data, 4):
        assert not set(truth_config[held]) & set(truth_config[~held])


def test_components_agree_with_scipys_graph_search():
    """The configurations' connected components (numpy label propagation) against scipy.sparse.csgraph
    on 300 random graphs (seeded: 1..199 nodes, up to three edges per node, self-loops and repeats
    included) and a 5000-node chain, the propagation's slowest case."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rng = np.random.default_rng(29)
    for _ in range(300):
        n = int(rng.integers(1, 200))
        a, b = rng.integers(0, n, (2, int(rng.integers(0, 3 * n))))
        _, labels = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)), directed=False)
        _, first, inverse = np.unique(labels, return_index=True, return_inverse=True)
        assert np.array_equal(grouping._components(n, a, b), np.argsort(np.argsort(first))[inverse])
    a = np.arange(4999)[::-1]
    assert np.all(grouping._components(5000, a, a + 1) == 0)


def test_reported_held_out_rms_matches_leave_configurations_out():
    """identify's 4-fold figure against an independent estimate built here: leave one configuration
    out (36 fits, each predicting the 8 repeats of the configuration it did not see). The row-wise
    4-fold figure, built here too, shows what the grouping corrects. Over 15 draws (seeds of the truth,
    the configurations and the noise: (3, 4, 7), the module's campaign, and (k, 10 + k, 20 + k) for
    k = 1..14): the 4-fold figure near leave-one-configuration-out, the row-wise figure optimistic on
    every draw and by more than 15% in the median, and on every draw the row-wise figure below the
    grouped one. This test took the module's draw alone and asserted the 4-fold figure within 15% of
    LOCO (0.8% there); over 59 draws (an audit, thirty-second session) it was 15-20% off on four (36
    configurations, 4 folds: each fold's fit sees 27) and the row-wise one at 0.851 on one. Measured
    on these 15: |4-fold / LOCO - 1| from 0.008 to 0.187, median 0.075 (a guess of 0.05 for the
    median, made before, did not hold); row-wise / LOCO 0.71-0.81. Asserted, a statement of these
    15 rather than a hold-out: the median within 10%, every draw within 25%."""
    robot = kincal.load_robot("kr500")
    off, optimistic = [], []
    for seeds in [(3, 4, 7)] + [(k, 10 + k, 20 + k) for k in range(1, 15)]:
        data, truth_config = _repeated(seeds=seeds)
        res = ident.identify(robot, data, k_folds=4, effects="joint_compliance")  # the model without the effect
        v = res.validation
        assert v["configurations"] == CONFIGS and v["scheme"] == "4-fold, whole configurations"
        loco = _held_rms(robot, data, res.effects, [truth_config == c for c in range(CONFIGS)])
        perm = np.random.default_rng(11).permutation(len(truth_config))
        rowwise = _held_rms(robot, data, res.effects, [np.isin(np.arange(len(perm)), perm[i::4]) for i in range(4)])
        off.append(abs(v["after_rms_mm"] / loco - 1))
        optimistic.append(rowwise / loco)
        assert rowwise < v["after_rms_mm"], seeds
    print("|4-fold / LOCO - 1|:", np.round(off, 3), "row-wise / LOCO:", np.round(optimistic, 3))
    assert np.median(off) <= 0.10 and max(off) <= 0.25, off
    assert np.median(optimistic) < 0.85 and max(optimistic) < 1, optimistic   # splitting rows is optimistic


def test_identify_command_states_the_scheme(tmp_path, repeated):
    data, _ = repeated
    robot = kincal.load_robot("kr500")
    (tmp_path / "m.csv").write_text(ident.measurements_csv(data, robot.dof))
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out",
            str(tmp_path / "model.json"), "--holdout", "0.25")
    assert r.returncode == 0, r.stderr
    assert f"25% held out, whole configurations ({CONFIGS} configurations: rows with equal joint angles" in r.stdout
    v = json.loads((tmp_path / "model.json").read_text())["identification"]["validation"]
    assert v["configurations"] == CONFIGS and v["held_rows"] == 9 * REPEATS


def test_a_failed_fold_says_it_is_a_fold():
    """A fold whose fit the core refuses (too few rows) is named as a fold in the error: the core's
    count of rows is the fold's, not the file's."""
    import numpy as np
    import pytest

    from kincal.calibration import identify as ident

    def refuses(data, opts):
        raise ValueError(f"m.csv: the {len(data['pose'])} measured points of ...: too few or too similar poses")

    data = kincal.MeasurementSet({"pose": np.arange(10), "q_deg": np.zeros((10, 6)), "xyz": np.zeros((10, 3)),
                                  "target": np.zeros(10, int), "source": "m.csv"})
    held = [np.arange(10) < 2, np.arange(10) >= 2]
    with pytest.raises(ValueError, match=r"cross-validation fold 1 of 2 \(the model fitted without 2 held-out rows\): "
                                         r"m.csv: the 8 measured points"):
        ident._fold_errors(lambda train: (refuses(train, None), None), data, held, None)
