"""What ``lookalike track`` runs, as a library: detections read or found, trackers fed, results written; the
command line only parses options and prints."""
