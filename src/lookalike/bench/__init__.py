"""Benchmarks as a library: the datasets, the runners, the leaderboard and the parameter presets
behind ``lookalike bench``; ``benchmarks/`` scripts and tests import it, the CLI prints it.

- :mod:`lookalike.bench.datasets`: real sequences (MOT15, pigs, HexBug, synthetic MOT17) and cuts,
- :mod:`lookalike.bench.synthetic`: the synthetic detector model,
- :mod:`lookalike.bench.runner`: entries, tracking and scoring jobs on any backend,
- :mod:`lookalike.bench.leaderboard`: ranks, the combined ranking, plots,
- :mod:`lookalike.bench.peers`: other libraries' trackers (optional imports),
- :mod:`lookalike.bench.presets`: parameter presets (JSON files saying what they were chosen on),
- :mod:`lookalike.bench.ident`, :mod:`~lookalike.bench.divers`, :mod:`~lookalike.bench.pixels`,
  :mod:`~lookalike.bench.experiments`: the simulated benches (robots, divers, pixels, controls),
- :mod:`lookalike.bench.tables`: writing table rows as JSON/CSV."""
