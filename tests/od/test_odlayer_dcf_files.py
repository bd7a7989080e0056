"""What the loader accepts from other tools' files: empty identity numbers (CANopenNode), an absent ProductNumber,
TIME values as "days ms" (Lely) and a DCF's configured values (ParameterValue, ``[xxxxValue]``)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.od import DataType, DictionaryError, load_dictionary
from servostudio.od.eds_values import TIME_MAX_DAYS, TIME_MAX_MS, ValueSyntaxError, parse_value, time_text

DCFCHK = Path(sys.executable).parent / "dcfchk"
SPEED_LIMIT = "[2100]\nParameterName=Speed limit\nDataType=0x0006\nAccessType=rw\nLowLimit=10\nHighLimit=6000\n"


def dcfchk_accepts(path: Path) -> bool:
    """The reference: what lely's dcfchk accepts, the loader must accept too."""
    result = subprocess.run([str(DCFCHK), "-n", "1", str(path)], capture_output=True, text=True, timeout=60)
    return result.returncode == 0


@pytest.fixture
def dcfchk_eds(mini_eds: str) -> str:
    """The mini EDS without its TPDO (dcfchk needs a mapping object beside every PDO communication object)."""
    text = mini_eds.replace("SupportedObjects=2\n1=0x1800\n2=0x6041", "SupportedObjects=1\n1=0x6041")
    return re.sub(r"\[1800\].*?(?=\[6041\])", "", text, flags=re.S)


@pytest.mark.parametrize(
    ("old", "new", "vendor", "product"),
    [
        ("VendorNumber=0x12", "VendorNumber=", 0x12, 0x34),
        ("ProductNumber=0x34", "ProductNumber=", 0x12, 0x34),
        ("VendorNumber=0x12\n", "", 0x12, 0x34),
        ("ProductNumber=0x34\n", "", 0x12, 0x34),
    ],
    ids=["empty vendor", "empty product", "absent vendor", "absent product"],
)
def test_an_empty_identity_number_reads_like_an_absent_one(
    write_files, dcfchk_eds: str, old: str, new: str, vendor: int, product: int
) -> None:
    path = write_files(eds=dcfchk_eds.replace(old, new), props=None)
    assert dcfchk_accepts(path)
    od = load_dictionary(path)
    assert (od.vendor_id, od.product_code) == (vendor, product)


def test_empty_identity_numbers_without_identity_defaults_are_zero(write_files, dcfchk_eds: str) -> None:
    """CANopenNode's generated profiles: ``VendorNumber=``, ``ProductNumber=`` and 0x1018 without defaults."""
    text = dcfchk_eds.replace("VendorNumber=0x12", "VendorNumber=").replace("ProductNumber=0x34", "ProductNumber=")
    text = text.replace("DefaultValue=0x12\n", "").replace("DefaultValue=0x34\n", "")
    path = write_files(eds=text, props=None)
    assert dcfchk_accepts(path)
    od = load_dictionary(path)
    assert (od.vendor_id, od.product_code, od.revision) == (0, 0, 1)


def test_an_absent_product_number_is_not_compared_with_the_identity(write_files, dcfchk_eds: str) -> None:
    text = dcfchk_eds.replace("ProductNumber=0x34\n", "").replace("DefaultValue=0x34", "DefaultValue=0x99")
    path = write_files(eds=text, props=None)
    assert dcfchk_accepts(path)
    assert load_dictionary(path).product_code == 0x99


def test_a_given_product_number_must_still_agree(write_files, mini_eds: str) -> None:
    path = write_files(eds=mini_eds.replace("ProductNumber=0x34", "ProductNumber=0x35"), props=None)
    with pytest.raises(DictionaryError, match=r"ProductNumber 0x35 differs from 0x1018,2 \(0x34\)"):
        load_dictionary(path)


@pytest.mark.parametrize(
    ("old", "new", "section", "reason"),
    [
        ("[OptionalObjects]\nSupportedObjects=2", "[OptionalObjects]\nSupportedObjects=", "OptionalObjects", "empty"),
        ("[OptionalObjects]\nSupportedObjects=2\n", "[OptionalObjects]\n", "OptionalObjects", "missing"),
        ("ParameterName=Speed limit", "ParameterName=", "2100", "empty"),
        ("ParameterName=Speed limit\n", "", "2100", "missing"),
        ("Statusword\nDataType=0x0006", "Statusword\nDataType=", "6041", "empty"),
        ("Statusword\nDataType=0x0006\n", "Statusword\n", "6041", "missing"),
        ("Statusword\nDataType=0x0006\nAccessType=ro", "Statusword\nDataType=0x0006\nAccessType=", "6041", "empty"),
        ("1=0x1000", "1=", "MandatoryObjects", "empty"),
    ],
)
def test_a_required_key_is_reported_missing_or_empty(
    write_files, mini_eds: str, old: str, new: str, section: str, reason: str
) -> None:
    assert old in mini_eds
    text = mini_eds.replace(old, new, 1)
    with pytest.raises(DictionaryError) as caught:
        load_dictionary(write_files(eds=text, props=None))
    assert caught.value.section == section
    assert caught.value.reason.endswith(f"is {reason}"), caught.value.reason


# --- TIME_OF_DAY / TIME_DIFFERENCE -------------------------------------------------------------------------------


@pytest.mark.parametrize("code", ["0x000C", "0x000D"])
def test_time_values_written_as_days_and_milliseconds_are_read(write_files, dcfchk_eds: str, code: str) -> None:
    time_entry = f"[2100]\nParameterName=Speed limit\nDataType={code}\nAccessType=rw\nDefaultValue=365 43200000\n"
    text = dcfchk_eds.replace(SPEED_LIMIT + "DefaultValue=3000\n", time_entry)
    path = write_files(eds=text, props=None)
    assert dcfchk_accepts(path)
    assert load_dictionary(path)[0x2100, 0].default == 365 << 32 | 43_200_000


@given(st.integers(0, TIME_MAX_DAYS), st.integers(0, TIME_MAX_MS), st.booleans())
def test_days_and_milliseconds_read_back_as_the_time_integer(days: int, ms: int, hexadecimal: bool) -> None:
    text = f"{days:#x} {ms:#x}" if hexadecimal else f"{days} {ms}"
    value, _ = parse_value(DataType.TIME_OF_DAY, text)
    assert value == days << 32 | ms
    assert parse_value(DataType.TIME_DIFFERENCE, time_text(days << 32 | ms))[0] == value


@given(st.integers(0, (1 << 48) - 1))
def test_the_single_integer_form_still_reads(value: int) -> None:
    assert parse_value(DataType.TIME_OF_DAY, str(value))[0] == value


@pytest.mark.parametrize("text", ["65536 0", "0 268435456", "-1 5", "1 2 3", "1 x"])
def test_days_or_milliseconds_out_of_range_are_refused(text: str) -> None:
    with pytest.raises(ValueSyntaxError):
        parse_value(DataType.TIME_OF_DAY, text)


# --- DCF configured values ---------------------------------------------------------------------------------------


def test_parameter_values_are_kept_beside_the_defaults(write_files, mini_eds: str) -> None:
    text = mini_eds.replace("DefaultValue=3000", "DefaultValue=3000\nParameterValue=0x64")
    text = text.replace("DefaultValue=$NODEID+0x180", "DefaultValue=$NODEID+0x180\nParameterValue=$NODEID+0x280")
    text = text.replace("[6041]\nParameterName=Statusword", "[6041]\nParameterName=Statusword\nParameterValue=7")
    od = load_dictionary(write_files(eds=text, props=None))
    speed, cob_id, status = od[0x2100, 0], od[0x1800, 1], od[0x6041, 0]
    assert (speed.default, speed.parameter_value, speed.parameter_expr) == (3000, 0x64, "0x64")
    assert (cob_id.parameter_value_for(5), cob_id.parameter_expr, cob_id.parameter_node_offset) == (
        0x285,
        "$NODEID+0x280",
        0x280,
    )
    assert (status.default, status.parameter_value) == (None, 7)  # only a ParameterValue: kept all the same
    assert od[0x2000, 1].parameter_value is None


def test_a_compact_value_section_configures_its_sub_indices(write_files, mini_eds: str) -> None:
    text = mini_eds + "\n[2000Value]\nNrOfEntries=2\n1=-7\n3=0x10\n"
    od = load_dictionary(write_files(eds=text, props=None))
    assert [od[0x2000, sub].parameter_value for sub in (1, 2, 3)] == [-7, None, 16]
    assert [od[0x2000, sub].default for sub in (1, 2, 3)] == [5, 5, 5]


@pytest.mark.parametrize(
    ("value_section", "reason"),
    [("NrOfEntries=2\n1=-7\n", "NrOfEntries=2 but 1 entries"), ("NrOfEntries=1\n1=500\n", "outside the limits")],
)
def test_a_compact_value_section_is_checked(write_files, mini_eds: str, value_section: str, reason: str) -> None:
    with pytest.raises(DictionaryError, match=reason) as caught:
        load_dictionary(write_files(eds=mini_eds + f"\n[2000Value]\n{value_section}", props=None))
    assert caught.value.section == "2000Value"


_IDENTITY_FORMS = st.sampled_from(["given", "empty", "absent"])


@given(st.integers(0, 0xFFFFFFFF), st.integers(0, 0xFFFFFFFF), _IDENTITY_FORMS, _IDENTITY_FORMS)
def test_identity_is_the_device_info_number_else_the_identity_default(
    mini_eds: str,
    tmp_path_factory: pytest.TempPathFactory,
    vendor: int,
    product: int,
    vendor_form: str,
    product_form: str,
) -> None:
    """A given number wins (it agrees with the identity default here); an empty or absent one is the default."""
    # through placeholders: a vendor number of 0x34 must not be taken for the product's default
    text = (
        mini_eds.replace("DefaultValue=0x12", "DefaultValue=@vendor@")
        .replace("DefaultValue=0x34", "DefaultValue=@product@")
        .replace("@vendor@", f"{vendor:#x}")
        .replace("@product@", f"{product:#x}")
    )
    for key, value, form in (("VendorNumber", vendor, vendor_form), ("ProductNumber", product, product_form)):
        line = {"given": f"{key}={value:#x}\n", "empty": f"{key}=\n", "absent": ""}[form]
        text = re.sub(rf"^{key}=.*\n", line, text, flags=re.M)
    path = tmp_path_factory.mktemp("identity") / "mini.eds"
    path.write_text(text, encoding="utf-8")
    od = load_dictionary(path)
    assert (od.vendor_id, od.product_code) == (vendor, product)
