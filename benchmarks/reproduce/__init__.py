"""Reproduce the thesis's experiments: a registry of experiments run by one runner, with
plots and a report. Entry point: ``python -m benchmarks.run_all`` (see `reproduce.cli`)."""
from .budgets import BUDGETS, Budget
from .registry import EXPERIMENTS, REGISTRY, Experiment

__all__ = ["BUDGETS", "Budget", "EXPERIMENTS", "REGISTRY", "Experiment"]
