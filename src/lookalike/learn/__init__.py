"""Training: the LSTM and set networks (torch), their data from the simulator and from recordings, the appearance,
heading and detector models. Inference of the shipped networks lives with the trackers
(:mod:`lookalike.trackers.lstm`, :mod:`lookalike.trackers.set`)."""
