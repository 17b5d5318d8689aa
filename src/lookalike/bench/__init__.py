"""Benchmarks as a library behind ``lookalike bench`` (the CLI prints them): real datasets, runners and the leaderboard,
other libraries' trackers (:mod:`~lookalike.bench.peers`), parameter presets, and the simulated benches."""
