"""Proofreading identities: doubtful ranges, corrections that re-solve a closed set of known size (or plain edits
without one), undo, and an export with a corrections log that can be replayed (docs/howto/proofread.md).

A correction in a closed set of N fixes identities on the solver's tracklets: a swap or assign from frame ``k`` fixes
the tracklets just before ``k`` to their current ids and those from ``k`` on to the corrected ones (cut at ``k``); a
split keeps the pieces before and after ``k`` apart; a merge fixes every piece of both tracks to one id; a delete
leaves the track's tracklets out. Every later correction is solved with all earlier ones; when they
conflict, the latest wins and the earlier ones in the way are dropped."""

from lookalike.proofread.edits import KINDS, Change, Correction, apply_edit, changes
from lookalike.proofread.session import Doubt, Session

__all__ = ["KINDS", "Change", "Correction", "Doubt", "Session", "apply_edit", "changes"]
