"""Simulated TTA-PRO PROFIBUS-DP slaves: the FDL/DP station, the PKW parameter channel, the PZD state machine of
the positioner on the shared plant and physics, reachable as a TCP byte stream or a pseudo-terminal
(docs/profibus.md §6). Like the CANopen simulator it speaks only bytes and never imports drive/, services/ or api/.
"""

PROFIBUS_DEVICES = frozenset({"ttapro"})
"""Device keys that are PROFIBUS-DP slaves rather than CANopen nodes."""
