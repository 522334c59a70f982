"""The ``games`` unit kind: a real game as objects, box FQI against DQN, PPO, the random and a
scripted policy, end to end at the tiny budget (Atari episodes capped at 800 frames)."""
import importlib.util
import json
from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks.reproduce import BUDGETS, REGISTRY
from benchmarks.reproduce.cache import unit_path
from benchmarks.reproduce.cli import main
from benchmarks.reproduce.kinds import KINDS
from benchmarks.reproduce.kinds.games import _SCRIPTS, _ScriptedPolicy

from harness import TINY

pytestmark = pytest.mark.skipif(importlib.util.find_spec("ocatari") is None,
                                reason="needs the atari extra (ocatari)")


@pytest.mark.slow   # five learners on Freeway's emulator: two to three minutes
def test_an_atari_game_runs_every_learner_and_reference_end_to_end(tmp_path):
    report = main(["--budget", "tiny", "--only", "games_freeway", "--out", str(tmp_path),
                   "--no-progress"]).read_text()
    experiment = REGISTRY["games_freeway"]
    results = {label: json.loads(unit_path(tmp_path, TINY, "games_freeway", label,
                                           0).read_text())["result"]
               for label in experiment.settings}
    for label in ("box FQI", "DQN (rl-zoo3)", "PPO (rl-zoo3)"):
        result = results[label]
        steps = [s for s, _ in result["curve"]]
        assert steps == sorted(steps) and steps[-1] == result["total_timesteps"]
        assert steps[-1] >= round(experiment.params(label)["steps"] * TINY.control_scale)
        assert result["curve"][-1][1] == result["reward"] and result["train_seconds"] > 0
    # Freeway's reward is sparse: random play hardly crosses, always UP crosses every time
    assert results["scripted policy"]["reward"] > results["random policy"]["reward"]
    assert results["scripted policy"]["human_normalised"] == pytest.approx(
        results["scripted policy"]["reward"] / 29.6)
    assert results["random policy"]["curve"] == [[0, results["random policy"]["reward"]]]
    assert "| box FQI | 1 |" in report and "human-normalised" in report
    assert (tmp_path / "extra_games_freeway.png").stat().st_size > 5000


def test_the_games_experiments_and_their_budgets():
    kind = KINDS["games"]
    for name in ("games_pong", "games_freeway", "games_boxing"):
        experiment = REGISTRY[name]
        assert experiment.on_demand and experiment.seeds == 3
        assert experiment.params("box FQI")["steps"] >= 500_000
        assert kind.settings(experiment.params("DQN (rl-zoo3)")).atari
    highway = kind.settings(REGISTRY["games_highway"].params("DQN (highway-env)"))
    assert highway.steps == 20_000 and highway.hyperparams["gamma"] == 0.8
    assert not highway.atari and highway.game == "highway-fast-v0"
    assert BUDGETS["full"].game_frames is None and TINY.game_frames == 800
    with pytest.raises(ValueError, match="no scripted policy for 'Alien'"):
        kind.settings({"env_id": "AtariObjects-v0", "env_kwargs": {"game": "Alien"},
                       "learner": "scripted"})
    with pytest.raises(ValueError, match="needs env_kwargs\\['game'\\]"):
        kind.settings({"env_id": "AtariObjects-v0", "learner": "random"})
    with pytest.raises(ValueError, match="steps must be"):
        kind.settings({"env_id": "highway-fast-v0", "learner": "fqi"})
    with pytest.raises(ValueError, match="sampled_actions is for the DQN and PPO learners"):
        kind.settings({"env_id": "highway-fast-v0", "learner": "fqi", "steps": 10,
                       "sampled_actions": True})


def test_the_boxing_script_closes_in_keeps_off_level_and_punches_every_other_step():
    names = ("NOOP", "FIRE", "UP", "RIGHT", "LEFT", "DOWN", "UPRIGHT", "UPLEFT", "DOWNRIGHT",
             "DOWNLEFT")
    env = SimpleNamespace(type_names=("Clock", "Enemy", "Player"), action_names=names)
    policy = _ScriptedPolicy(_SCRIPTS["Boxing"](env))

    def enemy_at(x, y):     # a row [x, y, w, h, dx, dy, type] relative to the player
        return np.array([[x, y, 14.0, 46.0, 0.0, 0.0, 1.0]], dtype=np.float32)

    far, level, in_reach = enemy_at(40, 20), enemy_at(-10, -2), enemy_at(10, 6)
    # each position of the batch (an env) punches on its own every other step
    for expected in (["DOWNRIGHT", "DOWN", "FIRE"], ["DOWNRIGHT", "DOWN", "NOOP"],
                     ["DOWNRIGHT", "DOWN", "FIRE"]):
        actions, _ = policy.predict([far, level, in_reach])
        assert [names[a] for a in actions] == expected
    assert names[policy.predict([np.empty((0, 7), dtype=np.float32)])[0][0]] == "NOOP"
