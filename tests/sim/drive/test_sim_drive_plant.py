"""The hidden plant: JSON file, seed generation, validation with readable errors."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.sim.plant import Plant, PlantError


def test_json_round_trip(tmp_path):
    plant = Plant.from_seed(7)
    path = tmp_path / "axis.json"
    plant.write_json(path)
    assert Plant.from_json(path) == plant
    assert not list(tmp_path.glob(".*.tmp"))


def test_partial_json_keeps_defaults(tmp_path):
    path = tmp_path / "axis.json"
    path.write_text('{"pole_pairs": 5, "home_switch": [1.0, 2.5], "negative_limit_switch": null}')
    plant = Plant.from_json(path)
    assert plant.pole_pairs == 5
    assert plant.home_switch == (1.0, 2.5)
    assert plant.negative_limit_switch is None
    assert plant.torque_constant == Plant().torque_constant


def test_seed_is_deterministic_and_differs_between_seeds():
    assert Plant.from_seed(3) == Plant.from_seed(3)
    assert Plant.from_seed(3) != Plant.from_seed(4)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"pole_pairs": 5,}', r"axis.json:1: invalid JSON"),
        ("[1, 2]", r"axis.json:1: the plant must be a JSON object"),
        ('{"polepairs": 5}', r"axis.json: unknown key 'polepairs'"),
        ('{"pole_pairs": "5"}', r"axis.json: 'pole_pairs' must be an integer"),
        ('{"pole_pairs": 30}', r"axis.json: 'pole_pairs' must be 1..24"),
        ('{"phase_order": 1}', r"axis.json: 'phase_order' must be 0x5555"),
        ('{"inertia": 1}', r"axis.json: unknown key 'inertia'"),
        ('{"motor_inertia": -1}', r"axis.json: 'motor_inertia' must be > 0"),
        ('{"home_switch": [3, 1]}', r"'home_switch' must be \[low, high\] with low < high"),
        ('{"negative_limit_switch": -30}', r"'negative_limit_switch' \(-30.0\) must be above 'negative_hard_stop'"),
        ('{"has_brake": 1}', r"'has_brake' must be true or false"),
        ('{"feedback": "hall"}', r"'feedback' must be 'resolver' or 'encoder'"),
    ],
)
def test_bad_files_name_the_file_and_the_reason(tmp_path, text, message):
    path = tmp_path / "axis.json"
    path.write_text(text)
    with pytest.raises(PlantError, match=message):
        Plant.from_json(path)


def test_missing_file(tmp_path):
    with pytest.raises(PlantError, match="cannot read"):
        Plant.from_json(tmp_path / "nope.json")


json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**6), 10**6)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=5),
    lambda children: st.lists(children, max_size=3),
    max_leaves=5,
)
keys = st.sampled_from(
    [
        "pole_pairs",
        "phase_order",
        "torque_constant",
        "home_switch",
        "feedback",
        "has_brake",
        "negative_limit_switch",
        "encoder_counts",
        "coupling_stiffness",
        "bogus",
    ]
)


@settings(max_examples=200, deadline=None)
@given(st.dictionaries(keys, json_values, max_size=4))
def test_any_json_object_gives_a_plant_or_a_plant_error(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("plant") / "axis.json"
    path.write_text(json.dumps(data))
    try:
        plant = Plant.from_json(path)
    except PlantError as error:
        assert str(error).startswith(str(path))
    else:
        assert Plant.from_mapping(plant.to_mapping()) == plant


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32))
def test_every_seed_gives_a_valid_plant(seed):
    plant = Plant.from_seed(seed)
    assert 1 <= plant.pole_pairs <= 24
    assert plant.negative_limit_switch < plant.initial_position < plant.positive_limit_switch
