"""Offline closed-set identity: a whole result's tracklets assigned to N identities in one optimisation.

:func:`assign_identities` takes the rows of an online pass (any ids) and

1. cuts each track into tracklets at missing frames, jumps and (with ``contact_iou``) contacts
   (:func:`split_tracklets`); pieces under ``min_rows`` rows are set aside;
2. scores links between tracklet ends and later starts under a constant-velocity and a go-anywhere
   hypothesis, as Gaussian negative log-likelihoods, keeping the ``candidates`` cheapest (:func:`link_costs`);
3. picks at most N chains of tracklets with one HiGHS MILP (:func:`solve_chains`): a tracklet on no
   chain is clutter;
4. places the short pieces on the chains with a second MILP (:func:`place_short`);
5. writes ids 1..N, fills gaps up to ``fill_gap_s`` seconds and smooths boxes by a running median.

:class:`ChainConstraints` (a proofreader's corrections) cut tracks, fix a tracklet's identity, keep two tracklets on
different identities or leave a tracklet out; the MILP then solves with them.

:func:`track_closed_set` first runs the online pass (open-set ``boxtrack``, ``n_init=1``). Positions are
pixels. The method and its parameters: docs/closed-set.md."""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from typing import Any

import numpy as np

from lookalike.trackers.offline.appearance import (
    UNTRUSTED_SHARE,
    cut_at_merges,
    fit_identity_space,
    look_margins,
    single_rows,
    with_appearance,
)
from lookalike.trackers.offline.closed_set_config import ClosedSetConfig
from lookalike.trackers.offline.confidence import by_frame_and_id, require_frame_rate
from lookalike.trackers.offline.constraints import (
    ChainConstraints,
    chain_ids,
    constraint_marks,
    cut_tracklets,
    holds,
    tracklet_of,
    with_marks,
)
from lookalike.trackers.offline.gap_fill import fill_gaps, smooth_boxes
from lookalike.trackers.offline.merges import hold_in_merges, place_in_merges
from lookalike.trackers.offline.online_look import LookIdentities, shape_lookup
from lookalike.trackers.offline.tracklets import (
    Tracklet,
    checked_rows,
    link_costs,
    motion_scale,
    row_centres,
    row_sizes,
    row_steps,
    split_tracklets,
)
from lookalike.trackers.registry import make_tracker, tracker_class
from lookalike.types import Detections, Frame
from lookalike.types.mot_table import tracks_to_rows

__all__ = ["ChainConstraints", "ClosedSetConfig", "Tracklet", "assign_identities", "closed_set_and_look",
           "closed_set_input", "link_costs", "motion_scale", "place_short", "smoothing_window", "solve_chains",
           "split_tracklets", "track_closed_set"]


def solve_chains(lengths: np.ndarray, links: tuple[np.ndarray, np.ndarray, np.ndarray], n_chains: int,
                 tracklet_cost: float, time_limit_s: float = 60.0, start_cost: np.ndarray | None = None,
                 end_cost: np.ndarray | None = None, marks: Sequence[tuple[Collection[int], Collection[int]]] = (),
                 excluded: Collection[int] = ()) -> list[list[int]]:
    """At most ``n_chains`` disjoint chains of tracklets (lists of indices in time order) maximising the rows covered
    minus ``tracklet_cost`` per tracklet used minus the link costs and the costs of starting (``start_cost[i]``) or
    ending (``end_cost[i]``) a chain at tracklet ``i``, by HiGHS MILP.

    Variables: ``x`` (tracklet used), ``y`` (link used), ``a`` (chain starts here), ``b`` (chain ends here); flow
    conservation ``a_i + Σ_j y_ji = x_i = b_i + Σ_j y_ij`` and ``Σ a_i ≤ n_chains``.

    Each of ``marks`` is ``(on, off)``: one chain carries the mark, it holds every tracklet of ``on`` and none of
    ``off`` (per mark, one unit of flow along the used links, from a chain head to a chain end, through every ``on``
    and over only the tracklets linked to and from each of them: :func:`~.constraints.with_marks`). Tracklets in
    ``excluded`` are on no chain. Raises ValueError when the constraints cannot all hold."""
    n = len(lengths)
    src, dst, cost = links
    m = len(src)
    if n == 0 or n_chains < 1:
        return []
    from scipy import sparse  # imported on first use: scipy.optimize and scipy.sparse are slow to import
    from scipy.optimize import Bounds, LinearConstraint, milp

    # variable blocks: x [0, n), y [n, n+m), a [n+m, 2n+m), b [2n+m, 3n+m)
    c = np.concatenate([-(np.asarray(lengths, float) - tracklet_cost), cost,
                        np.zeros(n) if start_cost is None else np.asarray(start_cost, float),
                        np.zeros(n) if end_cost is None else np.asarray(end_cost, float)])
    eye = sparse.identity(n, format="csr")
    into = sparse.csr_matrix((np.ones(m), (dst, np.arange(m))), shape=(n, m))
    out = sparse.csr_matrix((np.ones(m), (src, np.arange(m))), shape=(n, m))
    zero = sparse.csr_matrix((n, n))
    conserve_in = sparse.hstack([-eye, into, eye, zero])
    conserve_out = sparse.hstack([-eye, out, zero, eye])
    chains = sparse.hstack([sparse.csr_matrix((1, n + m)), sparse.csr_matrix(np.ones((1, n))),
                            sparse.csr_matrix((1, n))])
    A = sparse.vstack([conserve_in, conserve_out, chains]).tocsr()
    lo = np.concatenate([np.zeros(2 * n), [0.0]])
    hi = np.concatenate([np.zeros(2 * n), [float(n_chains)]])
    upper = np.ones(len(c))
    upper[list(excluded)] = 0.0
    lower = np.zeros(len(c))
    if marks:
        A, lo, hi, c, lower, upper = with_marks(A, lo, hi, c, lower, upper, n, (src, dst), marks)
    res = milp(c, constraints=LinearConstraint(A, lo, hi), integrality=np.ones(len(c)), bounds=Bounds(lower, upper),
               options={"time_limit": time_limit_s})
    if res.x is None and (marks or len(excluded)):
        raise ValueError(f"closed-set assignment: the constraints cannot all hold ({res.message})")
    if res.x is None:
        raise RuntimeError(f"closed-set assignment: the MILP solver found no solution ({res.message})")
    x = np.round(res.x).astype(int)
    used_link = x[n:n + m] > 0
    nxt = dict(zip(src[used_link].tolist(), dst[used_link].tolist()))
    heads = np.flatnonzero(x[n + m:2 * n + m] > 0)
    result = []
    for h in heads:
        chain, k = [int(h)], int(h)
        while k in nxt:
            k = nxt[k]
            chain.append(k)
        result.append(chain)
    return result


def _chain_position(block: np.ndarray, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centres ``(k, 2)`` px of a chain (rows sorted by frame) interpolated at ``frames`` (held beyond its
    ends) and the distance (frames) from each to the chain's nearest row; inf where it has a row there."""
    f = block[:, 0]
    c = row_centres(block)
    pos = np.column_stack([np.interp(frames, f, c[:, 0]), np.interp(frames, f, c[:, 1])])
    idx = np.clip(np.searchsorted(f, frames), 0, len(f) - 1)
    near = np.minimum(np.abs(f[idx] - frames), np.abs(f[np.maximum(idx - 1, 0)] - frames))
    return pos, np.where(near == 0, np.inf, near)


def place_short(short: list[Tracklet], chains: list[np.ndarray], scale: tuple[float, float, float],
                config: ClosedSetConfig | None = None) -> np.ndarray:
    """Chain index (or -1, clutter) of every short tracklet: an assignment of the short tracklets to the chains' gaps by
    HiGHS MILP. A piece costs ``link_cost + ½ z² + 2 ln(σ / (pos_sigma·size))`` minus its rows (a link's negative
    log-likelihood), ``z`` its mean miss from the chain's interpolated centre over ``σ = pos_sigma·size + speed·g``
    (``g`` frames to the chain's nearest row); only pieces that earn more than they cost are placed; pieces overlapping
    in time never go to the same chain, nor to frames where the chain has rows."""
    cfg = config or ClosedSetConfig()
    out = np.full(len(short), -1, dtype=int)
    if not short or not chains:
        return out
    size, speed, _ = scale
    pp, cc, cost = [], [], []
    for p, t in enumerate(short):
        frames = t.rows[:, 0]
        for c, block in enumerate(chains):
            pos, near = _chain_position(block, frames)
            if np.isinf(near).any():
                continue
            base = cfg.pos_sigma * size
            spread = base + speed * near
            z = float(np.mean(np.linalg.norm(pos - row_centres(t.rows), axis=1) / spread))
            nll = 0.5 * z**2 + 2 * float(np.mean(np.log(spread / base)))
            if z <= cfg.max_z and cfg.link_cost + nll < len(t):
                pp.append(p)
                cc.append(c)
                cost.append(cfg.link_cost + nll - len(t))
    if not pp:
        return out
    from scipy import sparse  # imported on first use: scipy.optimize and scipy.sparse are slow to import
    from scipy.optimize import Bounds, LinearConstraint, milp

    pp_a, cc_a, cost_a = np.array(pp), np.array(cc), np.array(cost)
    m = len(pp_a)
    rows_a = [sparse.csr_matrix((np.ones(m), (pp_a, np.arange(m))), shape=(len(short), m))]
    span = np.array([(t.first, t.last) for t in short])
    clash = []
    for c in np.unique(cc_a):
        idx = np.flatnonzero(cc_a == c)
        for a in range(len(idx)):
            for b in range(a + 1, len(idx)):
                p, q = pp_a[idx[a]], pp_a[idx[b]]
                if span[p, 0] <= span[q, 1] and span[q, 0] <= span[p, 1]:
                    clash.append((idx[a], idx[b]))
    if clash:
        ci = np.repeat(np.arange(len(clash)), 2)
        rows_a.append(sparse.csr_matrix((np.ones(2 * len(clash)), (ci, np.array(clash).ravel())),
                                        shape=(len(clash), m)))
    A = sparse.vstack(rows_a).tocsr()
    res = milp(cost_a, constraints=LinearConstraint(A, -np.inf, 1.0), integrality=np.ones(m), bounds=Bounds(0, 1),
               options={"time_limit": cfg.time_limit_s})
    if res.x is None:
        return out
    chosen = np.round(res.x).astype(bool)
    out[pp_a[chosen]] = cc_a[chosen]
    return out


def assign_identities(rows: np.ndarray, n_targets: int, frame_rate: float,
                      config: ClosedSetConfig | None = None, constraints: ChainConstraints | None = None,
                      shapes: np.ndarray | None = None, parts: np.ndarray | None = None) -> np.ndarray:
    """Result rows ``(k, 10)`` (any ids; 1-based frames, boxes in pixels) re-labelled with ids ``1..n_targets``
    by one global assignment of their tracklets (module doc); rows on no identity (clutter) are dropped
    and gaps of at most ``fill_gap_s`` inside an identity are interpolated. ``frame_rate`` in frames/s.
    ``constraints`` hold in the assignment (a tracklet fixed to identity ``j`` gets id ``j``; the other identities
    take the free ids in order of their start); ValueError when they name no input row or cannot all hold.
    ``shapes``: blob shape vectors ``(n, SHAPE_SIZE)`` that column 9 of ``rows`` indexes; with them, the look
    learned from the video weighs in every link (:mod:`~lookalike.trackers.offline.appearance`), merged blobs
    are left out of the tracklets, an identity whose first or last row leads into one stays in it
    (:func:`~lookalike.trackers.offline.merges.hold_in_merges`), and the identities in one are moved to its ends,
    or with ``parts`` (``(n, PART_SIZE)``, indexed as ``shapes``) onto its parts
    (:func:`~lookalike.trackers.offline.merges.place_in_merges`)."""
    return _assign(rows, n_targets, frame_rate, config, constraints, shapes, parts)[0]


def _assign(rows: np.ndarray, n_targets: int, frame_rate: float, config: ClosedSetConfig | None,
            constraints: ChainConstraints | None, shapes: np.ndarray | None,
            parts: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`assign_identities`'s rows and, where a look was learned, each row's look margin (the
    :func:`~lookalike.trackers.offline.appearance.look_margins` of the tracklet it came from; NaN for a row the look
    did not judge)."""
    cfg = config or ClosedSetConfig()
    if int(n_targets) < 1:
        raise ValueError(f"n_targets must be >= 1, got {n_targets}")
    require_frame_rate(frame_rate)
    rows = checked_rows(rows)
    pieces = split_tracklets(rows, cfg)
    if constraints is not None:
        pieces = cut_tracklets(pieces, constraints.cut)
    if not pieces:
        return rows.copy(), None
    crossing: list[Tracklet] = []
    if parts is not None and (shapes is None or len(parts) != len(shapes)):
        raise ValueError(f"parts: expected one per shape vector ({'no shapes' if shapes is None else len(shapes)}), "
                         f"got {len(parts)}")
    if shapes is not None:
        pieces, crossing = cut_at_merges(pieces, shapes)
        if constraints is not None:  # a merged piece that a constraint names is chained like the others
            named_merged = {tracklet_of(crossing, r) for r in constraints.rows() if holds(crossing, r)}
            pieces += [crossing[i] for i in sorted(named_merged)]
            crossing = [c for i, c in enumerate(crossing) if i not in named_merged]
    named = {tracklet_of(pieces, r) for r in constraints.rows()} if constraints is not None else set()
    tracklets = [t for i, t in enumerate(pieces) if len(t) >= cfg.min_rows or i in named] or pieces
    chained = {id(t) for t in tracklets}
    short = [t for t in pieces if len(t) < cfg.min_rows and tracklets is not pieces and id(t) not in chained]
    links = link_costs(tracklets, frame_rate, cfg)
    space = fit_identity_space(tracklets, shapes) if shapes is not None else None
    if space is not None:
        assert shapes is not None
        links = with_appearance(tracklets, links, shapes, space)
    lo, hi = rows[:, 0].min() + cfg.velocity_frames, rows[:, 0].max() - cfg.velocity_frames
    start_cost = np.array([cfg.edge_cost if t.first > lo else 0.0 for t in tracklets])
    end_cost = np.array([cfg.edge_cost if t.last < hi else 0.0 for t in tracklets])
    fixed: dict[int, int] = {}
    marks: list[tuple[Collection[int], Collection[int]]] = []
    excluded: list[int] = []
    if constraints is not None:
        fixed, marks, excluded, links = constraint_marks(tracklets, constraints, int(n_targets), links, cfg)
    chains = solve_chains(np.array([len(t) for t in tracklets]), links, int(n_targets), cfg.tracklet_cost,
                          cfg.time_limit_s, start_cost, end_cost, marks, excluded)
    chains.sort(key=lambda ch: (tracklets[ch[0]].first, tracklets[ch[0]].rows[0, 2]))
    blocks = [np.vstack([tracklets[i].rows for i in chain]) for chain in chains]
    placed = place_short(short, blocks, motion_scale(tracklets), cfg)
    ids = chain_ids(chains, fixed, int(n_targets))
    margin = None if space is None or shapes is None else look_margins(tracklets, chains, shapes, space)
    out = []
    for c, block in enumerate(blocks):
        extra = [short[p].rows for p in np.flatnonzero(placed == c)]
        block = np.vstack([block, *extra]).copy()
        block[:, 1] = ids[c]
        out.append(block)
    merged = np.vstack(out) if out else np.zeros((0, 10))
    merged = merged[np.lexsort((merged[:, 1], merged[:, 0]))]
    max_fill = len(np.unique(merged[:, 0])) + int(merged[:, 0].max(initial=0)) if math.isinf(cfg.fill_gap_s) else round(
        cfg.fill_gap_s * frame_rate)
    if not len(merged):
        return merged, None
    filled = fill_gaps(merged, max_fill)
    if shapes is not None:
        filled[:, 7:10] = -1.0
        if crossing:  # the identities interpolated through (or held in) a merged blob, moved to its ends or parts
            filled = hold_in_merges(filled, [t.rows for t in crossing])
            measured = np.isin(filled[:, 0] * (n_targets + 1) + filled[:, 1], merged[:, 0] * (n_targets + 1)
                               + merged[:, 1])
            filled = place_in_merges(filled, measured, np.vstack([t.rows for t in crossing]), shapes, parts)
    result = smooth_boxes(filled, smoothing_window(merged, frame_rate, cfg))
    if margin is None:
        return result, None
    keys = [(tracklets[i].rows[:, 0], np.full(len(tracklets[i]), ids[c]), np.full(len(tracklets[i]), margin[i]))
            for c, chain in enumerate(chains) for i in chain]
    return result, by_frame_and_id(result, np.vstack([np.column_stack(k) for k in keys]))


def smoothing_window(rows: np.ndarray, frame_rate: float, config: ClosedSetConfig | None = None) -> int:
    """Odd window (frames) of the running median of an identity's boxes: at most ``smooth_s`` seconds and
    at most the frames in which a target typically moves ``smooth_move`` box sizes (median step between
    consecutive rows; box sizes √(w·h)), so slow targets are smoothed long and fast ones briefly."""
    cfg = config or ClosedSetConfig()
    steps = row_steps(rows)
    size = float(np.mean(row_sizes(rows))) if len(rows) else 1.0
    step = float(np.median(steps)) if len(steps) else 0.0
    frames = cfg.smooth_s * frame_rate
    if step > 0:
        frames = min(frames, cfg.smooth_move * size / step)
    return max(int(frames) // 2 * 2 + 1, 1)


def online_rows(det_rows: np.ndarray, frame_rate: float, n_frames: int | None = None,
                tracker: str = "boxtrack", *, vel_noise: float | None = None, index: bool = False,
                reported: bool = False, shapes: np.ndarray | None = None, **params: Any) -> np.ndarray:
    """Result rows of an online pass of ``tracker`` over detection rows ``(k, >=7)`` (1-based frames,
    boxes in pixels, score in column 7): only tracks matched to a detection, at that detection's box.
    ``vel_noise``: ``boxtrack``'s velocity noise (fraction of the box size per frame) when not its default
    (:class:`~lookalike.trackers.boxtrack.BoxTrack`'s hook; points as boxes use
    :data:`lookalike.io.points.POINT_VEL_NOISE`). ``index``: column 9 holds the detection's row number in
    ``det_rows``. ``reported``: instead, every track the tracker reports, as ``lookalike track`` writes it; then with
    ``shapes`` (one blob shape vector per detection row) and ``max_targets``, the slots' identities re-assigned by the
    look as ``--online`` does on blobs (:class:`~lookalike.trackers.offline.online_look.LookIdentities`)."""
    require_frame_rate(frame_rate)
    det_rows = checked_rows(det_rows)
    tracker_obj = make_tracker(tracker, **params)
    if vel_noise is not None:
        if tracker != "boxtrack":
            raise ValueError(f"vel_noise is a boxtrack setting, not one of {tracker!r}")
        boxtrack: Any = tracker_class(tracker)
        tracker_obj = boxtrack(tracker_obj.config, vel_noise=vel_noise)
    n_frames = int(det_rows[:, 0].max()) if n_frames is None and len(det_rows) else int(n_frames or 0)
    if len(det_rows) and det_rows[:, 0].max() > n_frames:
        raise ValueError(f"det_rows: frame {int(det_rows[:, 0].max())} is past n_frames ({n_frames}); give the "
                         "sequence's length, or None to take the last frame of the rows")
    order = np.argsort(det_rows[:, 0], kind="stable")
    det_rows = det_rows[order]
    bounds = np.searchsorted(det_rows[:, 0], np.arange(1, n_frames + 2))
    if reported and shapes is not None and params.get("max_targets"):
        lookup = shape_lookup(det_rows, np.asarray(shapes)[order], n_frames)
        tracker_obj = LookIdentities(tracker_obj, params["max_targets"], frame_rate, lookup)
    out = []
    for k in range(n_frames):
        block = det_rows[bounds[k]:bounds[k + 1]]
        dets = Detections(xywh=block[:, 2:6], score=block[:, 6]) if len(block) else Detections.empty()
        tracks = tracker_obj.update(Frame(index=k, time=k / frame_rate, detections=dets))
        if reported:
            out.extend(tracks_to_rows(k, tracks).tolist())
            continue
        for t in tracks:
            if t.detection_index is None or t.detection_index < 0:
                continue  # coasted: no detection behind it
            row = order[bounds[k] + t.detection_index] if index else -1
            out.append([k + 1, t.track_id, *block[t.detection_index, 2:6], 1.0, -1, -1, row])
    return np.array(out, dtype=float).reshape(-1, 10)


def closed_set_input(det_rows: np.ndarray, frame_rate: float, n_frames: int | None = None, *,
                     online: dict[str, Any] | None = None, vel_noise: float | None = None,
                     index: bool = False) -> np.ndarray:
    """The rows :func:`assign_identities` starts from: an open-set online ``boxtrack`` pass over detection rows with
    ``n_init=1`` (every detection enters some tracklet; the assignment decides what is clutter); ``online`` overrides
    its parameters, ``vel_noise`` and ``index`` as in :func:`online_rows`."""
    return online_rows(det_rows, frame_rate, n_frames, vel_noise=vel_noise, index=index,
                       **{"n_init": 1, **(online or {})})


def track_closed_set(det_rows: np.ndarray, n_targets: int, frame_rate: float, *, n_frames: int | None = None,
                     online: dict[str, Any] | None = None, config: ClosedSetConfig | None = None,
                     vel_noise: float | None = None, shapes: np.ndarray | None = None,
                     parts: np.ndarray | None = None, note: Callable[[str], None] | None = None) -> np.ndarray:
    """Offline closed-set tracking of detection rows ``(k, >=7)``: :func:`closed_set_input` (``online``,
    ``vel_noise``), then
    :func:`assign_identities` (``shapes``, ``parts``: one blob shape and parts vector per detection row, or None).
    Returns result rows
    ``(k, 10)`` with ids ``1..n_targets``. With ``shapes``, when more than
    :data:`~lookalike.trackers.offline.appearance.UNTRUSTED_SHARE` of the pass's blobs are not one animal's size, the
    online closed set's rows (``boxtrack`` with ``max_targets``, as ``track --targets N --online`` writes them) are
    returned instead, and ``note`` told why."""
    return closed_set_and_look(det_rows, n_targets, frame_rate, n_frames=n_frames, online=online, config=config,
                               vel_noise=vel_noise, shapes=shapes, parts=parts, note=note)[0]


def closed_set_and_look(det_rows: np.ndarray, n_targets: int, frame_rate: float, *, n_frames: int | None = None,
                        online: dict[str, Any] | None = None, config: ClosedSetConfig | None = None,
                        vel_noise: float | None = None, shapes: np.ndarray | None = None,
                        parts: np.ndarray | None = None,
                        note: Callable[[str], None] | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`track_closed_set`'s rows and, where it learned a look, each row's look margin (NaN for a row the look
    did not judge: merged blobs, short pieces, filled gaps; None without a look)."""
    if int(n_targets) < 1:
        raise ValueError(f"n_targets must be >= 1, got {n_targets}")
    for name, given in (("shapes", shapes), ("parts", parts)):
        if given is not None and len(given) != len(det_rows):
            raise ValueError(f"{name}: expected one per detection row ({len(det_rows)}), got {len(given)}")
    rows = closed_set_input(det_rows, frame_rate, n_frames, online=online, vel_noise=vel_noise,
                            index=shapes is not None)
    share = 1.0 - float(single_rows(rows, shapes).mean()) if shapes is not None and len(rows) else 0.0
    if share > UNTRUSTED_SHARE:
        if note is not None:
            note(f"note: {100 * share:.0f}% of the blobs are not one animal's size (merged, cut by the border or "
                 f"shadowed), too many to learn each one's look; the online closed set's result (--targets "
                 f"{n_targets} --online) is written instead")
        return online_rows(det_rows, frame_rate, n_frames, vel_noise=vel_noise, reported=True, shapes=shapes,
                           **{**(online or {}), "max_targets": int(n_targets)}), None
    return _assign(rows, n_targets, frame_rate, config, None, shapes, parts)
