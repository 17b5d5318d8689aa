"""Simulators that make labelled data."""

from lookalike.sim.boxes import BoxScene, BoxSceneConfig, simulate_boxes

__all__ = ["BoxScene", "BoxSceneConfig", "simulate_boxes"]
