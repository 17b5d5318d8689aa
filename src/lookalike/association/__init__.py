"""Assignment solver contract and association costs."""

from lookalike.association.costs import iou_cost
from lookalike.association.solver import Assignment, assign, max_weight_complete

__all__ = ["Assignment", "assign", "iou_cost", "max_weight_complete"]
