"""The first paragraph of each command's help, so that ``lookalike --help`` lists the commands without importing
their modules (``tests/test_first_runs.py`` checks this against the commands)."""

from __future__ import annotations

SUMMARIES = {
    'bench': 'Benchmarks that print tables (also written with --json/--csv).',
    'camera-sim': "A simulated camera: send each frame's detections to the node at the camera rate.",
    'demo': 'Simulate robots and divers, run every relevant tracker, write videos, plots and an HTML report.',
    'eval': 'Score trackers with HOTA, CLEAR MOT and identity metrics (values shown in %).',
    'label': 'Serve the labelling page: click detections to cycle their robot (left forward, right back).',
    'record-pixels': (
        'Render robot sequences, detect them from the pixels and write each as a labelled recording\n(pixel '
        'detections, renderer truth as labels, the simulated reports).'
    ),
    'render': 'Draw tracks (identity colours, ids, tails) on every frame of a video, or from above (--birdseye).',
    'render-robots': (
        'Draw a simulated robot sequence through the robot camera (640×480, 70°) as a video: the input of\n'
        '`lookalike track --video FILE --pipeline robots --reports SEQUENCE`.'
    ),
    'report': 'Build an HTML report (tables and bar charts, images embedded) from result files.',
    'robot-sim': (
        'A simulated robot: send heading reports to the node over a lossy, jittery link, receive\nthe team '
        'state, and print the error of its identified position against its true one (JSON).'
    ),
    'serve': (
        'Run the observer node: receive heading reports and detections over UDP, identify the\nrobots with a '
        'tracker, publish their positions at the camera rate. Logs are JSON Lines on\nstderr; send a '
        'status_request message for the counters.'
    ),
    'simulate': 'Simulate identical robots seen by an observer, with heading reports; write JSON Lines files.',
    'track': 'Run a tracker over MOTChallenge detections and write MOTChallenge results (on a video with --video).',
    'trackers': (
        'List the registered trackers, one line each (what each reads, what it is); --details NAME gives one\n'
        "tracker's parameters."
    ),
    'train': (
        'Train the association network on simulated sequences generated on the fly (or fine-tune it on '
        'labelled\nrecordings with --recordings, or search its hyper-parameters with --search).'
    ),
    'train-appearance': 'Train the small CNN embedding on crops of new rendered divers and export it to ONNX.',
    'train-detector': 'Train the HOG cascade robot detector and save it.',
    'train-heading': 'Train the heading classifier on rendered robots, report its held-out error and save it.',
    'tune': "Choose a tracker's parameters on labelled sequences; write them for `track --params`.",
}
"""Command name → the first paragraph of its help."""
