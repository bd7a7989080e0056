"""The option parser (request options → checked writes) on every input: either refused with BadOptions before
anything is written, or writes whose raw values are exactly the profile's codes."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.drive.access import Drive
from servostudio.drive.profiles import PROFILES
from servostudio.od import builtin_library
from servostudio.services.procedures import BadOptions
from servostudio.services.procedures.options import option_writes, shown

LIBRARY = builtin_library()
DRIVES = {device: Drive(None, 1, LIBRARY.load(device)) for device in ("xtrapulspac", "cd1k")}  # type: ignore[arg-type]
KEYS = st.sampled_from(["bandwidth", "filter", "speed_filter", "mode", "inductance_mh", "regulator", "colour"])
VALUES = st.one_of(
    st.sampled_from(["50", "75", "100", "standard", "anti-resonance", "max-stiffness", "auto", "0.5", "1", "2"]),
    st.sampled_from(["min-following-error", "min-overshoot", "high", "low"]),
    st.integers(-5, 200),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.none(),
)


@settings(max_examples=300, deadline=None)
@given(
    device=st.sampled_from(sorted(DRIVES)),
    name=st.sampled_from(["auto_tuning", "current_loop"]),
    given_options=st.dictionaries(KEYS, VALUES, max_size=5),
)
def test_options_are_refused_or_written_as_the_profile_codes_them(device, name, given_options):
    drive = DRIVES[device]
    description = PROFILES[device].procedures.get(name)
    if description is None:
        return
    try:
        writes = option_writes(drive, name, description, given_options)
    except BadOptions:
        return
    coded = {drive.profile.address(option.object) for option in description.options.values()}
    valued = {drive.profile.address(target) for target in description.values.values()}
    for variable, raw in writes:
        assert variable.key in coded | valued
        if variable.key in coded:
            sums = {sum(combination) for combination in _combinations(description, variable.key, drive)}
            assert raw in sums


def _combinations(description, key, drive):
    """Every sum of one code per option written to ``key``."""
    sets = [
        list(option.codes.values())
        for option in description.options.values()
        if drive.profile.address(option.object) == key
    ]
    combos = [[]]
    for codes in sets:
        combos = [[*combo, code] for combo in combos for code in codes]
    return combos


def test_a_result_shows_a_choice_alike_whether_given_as_number_or_text():
    """REST gives ``{"bandwidth": 100}``, the CLI ``"100"``: a saved result must not depend on the face used."""
    assert shown("auto_tuning", {"bandwidth": 100}) == shown("auto_tuning", {"bandwidth": "100"})
    assert shown("auto_tuning", {"bandwidth": 100.0, "speed_filter": 0.5})["speed_filter"] == "0.5"
    assert shown("current_loop", {"inductance_mh": 2.5}) == {"inductance_mh": 2.5}  # a physical value stays a number
