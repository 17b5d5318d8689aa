"""Vision: per-detection cues computed from images (appearance features, crops)."""
