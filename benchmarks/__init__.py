"""Benchmarks and the reproduction of the thesis (`benchmarks.reproduce`)."""
