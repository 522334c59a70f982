"""What the harness's tests share: the tiny budget, a finished FQI result, units of registry
settings."""
from benchmarks.reproduce import BUDGETS, REGISTRY
from benchmarks.reproduce.cache import save_unit, unit_path
from benchmarks.reproduce.units import Unit

TINY = BUDGETS["tiny"]
# A finished FQI unit's result at the tiny budget (2 iterations).
FQI_RESULT = {"rewards": [1.0, 2.0], "random_reward": -1.0, "seconds": 0.5}


def make_unit(out, experiment, label, seed=0, budget=TINY, samples=200):
    """The unit of a registry setting (a same_as setting's own, not its owner's)."""
    return Unit(experiment, label, seed, REGISTRY[experiment].params(label, budget), samples,
                budget, unit_path(out, budget, experiment, label, seed))


def save_sampling(out, label, seed):
    """A finished run of the sampling experiment's setting `label`; its path."""
    unit = make_unit(out, "sampling", label, seed, samples=TINY.samples)
    save_unit(unit, FQI_RESULT)
    return unit.path


def interrupt(*args):
    raise KeyboardInterrupt
