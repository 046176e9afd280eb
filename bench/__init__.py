"""Benchmarks of the generated code and generator; `make bench` (python -m bench.run) runs them all."""
