"""Operation modes of PNU 720 (TTA-PRO Profibus Communication Profile, Chapter 3, L1285-1296)."""

TORQUE = 1
POSITIONER = 4
SPEED_MODES = frozenset({2, 8, 16})
"""Speed mode with a PI, P or PI² regulator (the simulated loops run one PI regulator for all three)."""
MODES = SPEED_MODES | {TORQUE, POSITIONER}
