"""The 3D study of ``benchmarks/bench_sets.py --points`` at a tiny size: its point clouds,
the data file Set-Tree's part reads, and the box forests on resampled clouds."""
import json

import numpy as np
import pytest

from benchmarks import bench_sets
from benchmarks.bench_sets import (
    POINT_GROUPS,
    POINT_TEST_SIZES,
    POINT_TRAIN_SIZES,
    SHAPES,
    ResampledBoxForest,
    load_sets,
    make_data,
    resample,
    save_sets,
    solid_points,
)


def tiny_data(n_train=200, n_test=40, seed=0):
    return make_data("points", n_train, n_test, seed, POINT_TRAIN_SIZES, POINT_TEST_SIZES)


def test_clouds_are_3d_points_of_one_type_with_the_sizes_asked():
    (sets, labels), tests = tiny_data(100, 5)
    low, high = POINT_TRAIN_SIZES
    assert all(rows.shape[1] == 4 and low <= len(rows) <= high for rows in sets)
    assert all((rows[:, 3] == 0).all() for rows in sets)
    assert sorted(tests) == list(POINT_TEST_SIZES)
    for size, (test_sets, test_labels) in tests.items():
        assert [len(rows) for rows in test_sets] == [size] * 5 and len(test_labels) == 5
    # every shape drawn, none in more than twice its share
    counts = np.bincount(labels.astype(int), minlength=len(SHAPES))
    assert counts.min() > 0 and counts.max() < 2 * len(labels) / len(SHAPES)


def test_the_shapes_differ_where_a_box_can_see_it():
    # a corner of the cube holds points; the ball, cone and torus have none there
    rng = np.random.default_rng(0)
    corner = {shape.__name__: np.mean((solid_points(rng, shape, 5000) > 0.6).all(1))
              for shape in SHAPES}
    assert corner["cube"] > 0.001
    assert corner["ball"] == corner["cone"] == corner["torus"] == 0


def test_resample_draws_the_asked_number_of_rows_of_each_set():
    rng = np.random.default_rng(0)
    sets = [np.arange(40.0).reshape(10, 4), np.arange(400.0).reshape(100, 4)]
    small, large = resample(rng, sets, 64)
    assert small.shape == large.shape == (64, 4)
    assert len(np.unique(large[:, 0])) == 64                     # without replacement
    assert set(small[:, 0]) <= set(sets[0][:, 0])                # with replacement


def test_the_data_file_gives_back_the_same_sets(tmp_path):
    (sets, labels), tests = data = tiny_data(20, 3)
    save_sets(tmp_path / "points.npz", data)
    (loaded, loaded_labels), loaded_tests = load_sets(tmp_path / "points.npz")
    assert all(np.array_equal(a, b) for a, b in zip(sets, loaded, strict=True))
    np.testing.assert_array_equal(labels, loaded_labels)
    assert sorted(loaded_tests) == sorted(tests)
    for size in tests:
        assert all(np.array_equal(a, b) for a, b in zip(tests[size][0], loaded_tests[size][0],
                                                          strict=True))


def test_resampled_box_forest_beats_chance_at_every_test_size():
    (sets, labels), tests = tiny_data()
    forest = ResampledBoxForest(64, 0, column_groups=POINT_GROUPS, n_estimators=20).fit(sets, labels)
    for size, (test_sets, test_labels) in tests.items():
        accuracy = np.mean(forest.predict(test_sets) == test_labels)
        assert accuracy > 2 / len(SHAPES), (size, accuracy)      # chance: 1 / 5


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_points_study_writes_its_json_and_plot_without_settree(tmp_path, capsys):
    bench_sets.main(["--points", "--quick", "--out", str(tmp_path)])
    report = json.loads((tmp_path / "bench_points.json").read_text())
    assert (tmp_path / "bench_points.png").stat().st_size > 0
    models = [row["model"] for row in report["rows"]]
    assert len(models) == 4 and models[-1].startswith("Deep Sets")
    assert all(set(row["accuracy"]) == {str(n) for n in POINT_TEST_SIZES} for row in report["rows"])
    assert "Set-Tree is skipped" in capsys.readouterr().out
