"""Offline processing of whole results: tracklets, the closed-set global assignment and gap filling."""
