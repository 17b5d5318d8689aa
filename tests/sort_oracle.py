"""A deliberately plain, one-track-at-a-time SORT used as an oracle for the batched tracker.

Written from the SORT paper's description (per-track Kalman filter on [u, v, s, r], IoU Hungarian
matching, max_age/min_hits rules), with explicit loops and no shared code with lookalike.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment


def _to_z(b):
    x1, y1, x2, y2 = b
    w, h = x2 - x1, y2 - y1
    return np.array([x1 + w / 2, y1 + h / 2, w * h, w / h])


def _to_box(x):
    w = np.sqrt(x[2] * x[3])
    h = x[2] / w
    return np.array([x[0] - w / 2, x[1] - h / 2, x[0] + w / 2, x[1] + h / 2])


def _iou(a, b):
    w = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = w * h
    return inter / ((a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter)


class _Track:
    def __init__(self, box, tid):
        self.F = np.eye(7)
        self.F[0, 4] = self.F[1, 5] = self.F[2, 6] = 1
        self.H = np.eye(4, 7)
        self.R = np.diag([1.0, 1, 10, 10])
        self.P = np.diag([10.0, 10, 10, 10, 1e4, 1e4, 1e4])
        self.Q = np.diag([1.0, 1, 1, 1, 0.01, 0.01, 1e-4])
        self.x = np.concatenate([_to_z(box), np.zeros(3)])
        self.id = tid
        self.since_update = 0
        self.streak = 0

    def predict(self):
        if self.x[6] + self.x[2] <= 0:
            self.x[6] = 0.0
        self.x = self.F @ self.x
        self.P = self.F @ self.P @ self.F.T + self.Q
        if self.since_update > 0:
            self.streak = 0
        self.since_update += 1
        return _to_box(self.x)

    def update(self, box):
        self.since_update = 0
        self.streak += 1
        S = self.H @ self.P @ self.H.T + self.R
        K = self.P @ self.H.T @ np.linalg.inv(S)
        self.x = self.x + K @ (_to_z(box) - self.H @ self.x)
        self.P = (np.eye(7) - K @ self.H) @ self.P


class OracleSort:
    def __init__(self, max_age=1, min_hits=3, iou_threshold=0.3):
        self.max_age, self.min_hits, self.thr = max_age, min_hits, iou_threshold
        self.tracks: list[_Track] = []
        self.frame_count = 0
        self.next_id = 1

    def update(self, xyxy):
        """``xyxy (n, 4)`` -> list of ``(id, xyxy)`` reported this frame."""
        self.frame_count += 1
        predicted = []
        for t in list(self.tracks):
            p = t.predict()
            if np.any(np.isnan(p)):
                self.tracks.remove(t)
            else:
                predicted.append(p)
        pairs = []
        if len(xyxy) and self.tracks:
            iou = np.array([[_iou(d, p) for p in predicted] for d in xyxy])
            above = iou > self.thr
            if above.sum(1).max() == 1 and above.sum(0).max() == 1:
                cand = list(zip(*np.nonzero(above)))
            else:
                cand = list(zip(*linear_sum_assignment(-iou)))
            pairs = [(d, t) for d, t in cand if iou[d, t] >= self.thr]
        matched_d = {d for d, _ in pairs}
        for d, t in pairs:
            self.tracks[t].update(xyxy[d])
        for d in range(len(xyxy)):
            if d not in matched_d:
                self.tracks.append(_Track(xyxy[d], self.next_id))
                self.next_id += 1
        out = []
        for t in self.tracks:
            if t.since_update < 1 and (t.streak >= self.min_hits or self.frame_count <= self.min_hits):
                out.append((t.id, _to_box(t.x)))
        self.tracks = [t for t in self.tracks if t.since_update <= self.max_age]
        return out
