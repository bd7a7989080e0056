"""A simulated TTA-PRO driven in virtual time (the rig: ``tests/support/ttapro_rig.py``), without the FDL layer (the
station tests and the TCP acceptance cover that)."""

from __future__ import annotations

import pytest
from tests.support.ttapro_rig import Rig

from servostudio.od.pnu import builtin_parameter_list
from servostudio.od.pnu_model import ParameterDictionary


@pytest.fixture(scope="session")
def parameters() -> ParameterDictionary:
    return builtin_parameter_list()


@pytest.fixture
def rig(parameters: ParameterDictionary) -> Rig:
    return Rig(parameters)
