"""What FQI's two other forms of Q-function, Double FQI (``double``) and one regressor over
observations and actions (``action_input``), share: they learn CartPole from a few thousand
steps, and a save keeps them (and only an agent without a Q-function changes form)."""
import numpy as np
import pytest

from fqi import FQI, RandomPolicy, evaluate


@pytest.mark.parametrize("variant, n_regressors", [("double", 4), ("action_input", 1)])
def test_q_function_variant_learns_cartpole_and_saves(cartpole_fqi, tmp_path, variant,
                                                      n_regressors):
    """2,000 env steps: the greedy policy balances far longer than random play."""
    agent = cartpole_fqi(**{variant: True}).learn(total_timesteps=2000)
    assert len(agent.q_functions_) == n_regressors and agent.iteration == 20
    score = evaluate(agent, "CartPole-v1", seeds=range(10)).mean
    random_mean = evaluate(RandomPolicy("CartPole-v1", seed=0), "CartPole-v1",
                           seeds=range(10)).mean
    assert random_mean < 30 and score > 100, (random_mean, score)  # double: 21.3, 475
    agent.save(tmp_path / "agent.joblib")
    loaded = FQI.load(tmp_path / "agent.joblib")
    assert getattr(loaded, variant) is True
    obs = np.random.default_rng(0).normal(size=(50, 4))
    np.testing.assert_array_equal(loaded.q_values(obs), agent.q_values(obs))
    with pytest.raises(ValueError, match=f"{variant} cannot change once the agent has a Q-f"):
        FQI.load(tmp_path / "agent.joblib", **{variant: False})
    cartpole_fqi().save(tmp_path / "unfitted.joblib")
    assert getattr(FQI.load(tmp_path / "unfitted.joblib", **{variant: True}), variant) is True
