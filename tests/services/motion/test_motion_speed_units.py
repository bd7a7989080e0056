"""The quick test's speeds in the drive's own unit: the encoTRive takes rpm (its factory velocity factor), the
XtrapulsPac position units per second — a 100 rpm jog must not become 6827 rpm on an encoTRive."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from servostudio.drive.profiles import profile_for
from servostudio.services.motion.units import rpm_to_speed
from servostudio.services.procedures.units import speed_rad_s, user_speed


class _Raw(SimpleNamespace):
    raw: int


def drive_of(device: str, values: dict[str, int]) -> SimpleNamespace:
    profile = profile_for(device)
    return SimpleNamespace(profile=profile, read=lambda name: _Raw(raw=values[name]))


def test_an_encotrive_speed_is_in_rpm():
    encotrive = drive_of("encotrive", {})
    assert rpm_to_speed(encotrive, 100) == 100
    assert speed_rad_s(encotrive, 60) == pytest.approx(2 * math.pi)  # 60 rpm = 1 rev/s
    assert user_speed(encotrive, 2 * math.pi) == pytest.approx(60)


def test_an_xtrapulspac_speed_is_in_position_units_per_second():
    xtrapulspac = drive_of("xtrapulspac", {"position_factor_numerator": 1, "position_factor_denominator": 1})
    assert rpm_to_speed(xtrapulspac, 100) == round(100 * 4096 / 60)
