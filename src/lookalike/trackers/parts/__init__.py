"""Shared parts the trackers are composed of: the track table, lifecycle, calibration, motion fit, clutter,
coasting, closed-set slots, world-tracker rules, beacon identities and the detector-health monitor."""
