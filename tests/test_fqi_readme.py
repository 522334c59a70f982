"""The README's examples run: the estimator on sets of objects and FQI on CartPole-v1.

The examples it held before (the classifier and other units, FQI on an environment of one's
own with saving and loading, the game, the Atari and highway-env adapters) moved to the
pages of docs/ on those subjects, as doctests: tests/test_doctests.py runs every page's
doctests, and the last test here checks that each is still there, as a doctest."""
import doctest
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
_BLOCK = re.compile(r"^```python\n(?P<code>.*?)^```$", re.MULTILINE | re.DOTALL)


def _doctest_lines(page):
    """The example lines (``>>>`` and ``...``) of the doctest blocks of `page`."""
    return [line.lstrip()[4:] for match in _BLOCK.finditer(page.read_text(encoding="utf-8"))
            if ">>>" in match["code"] for line in match["code"].splitlines()
            if line.lstrip().startswith((">>>", "..."))]


def test_readme_examples_run():
    text = README.read_text(encoding="utf-8")
    prompts = sum(line.lstrip().startswith(">>>") for line in text.splitlines())
    result = doctest.testfile(str(README), module_relative=False)
    # every example is found (none lost to the parsing) and passes
    assert result.failed == 0 and result.attempted == prompts >= 15, (result, prompts)
    code = "\n".join(_doctest_lines(README))
    for line in ("forest = BoxExtraTreesRegressor(", "forest.score(X_test",
                 'agent = FQI(ExtraTreesRegressor(', '"CartPole-v1"',
                 "agent.learn(total_timesteps=", "evaluate(agent, "):
        assert line in code, line


# the README's former examples, by a line of each, and the page each moved to
MOVED = {
    "boxtrees.md": ["classifier = BoxExtraTreesClassifier(n_estimators=10, random_state=0)",
                    "pixels = [np.column_stack([s[:, :2] * 100, s[:, 2]]) for s in X]"],
    "fqi.md": ["class Walk(gym.Env):", "agent.save(path)",
               "FQI.load(path, env=env).q_values(np.array([3.0], dtype=np.float32)).shape"],
    "game.md": ['env = gym.make("ObjectWorld-v0", render_mode="rgb_array")',
                'worlds = gym.make_vec("ObjectWorld-v0", num_envs=400)',
                "envs.PaddedObjects(env, max_objects=128).observation_space.shape"],
    "games.md": ['env = gym.make("AtariObjects-v0", game="Pong", max_num_frames_per_episode=400)',
                 'highway = envs.HighwayObjects(gym.make("highway_env:highway-fast-v0"))'],
}


@pytest.mark.parametrize("page", MOVED)
def test_the_former_readme_examples_are_doctests_of_their_pages(page):
    code = "\n".join(_doctest_lines(ROOT / "docs" / page))
    for line in MOVED[page]:
        assert line in code, line
