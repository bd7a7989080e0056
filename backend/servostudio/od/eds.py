"""Load a CiA 306 EDS (plus its companion `.props`) into an `ObjectDictionary`, rejecting malformed files.

The checks mirror what lely's `dcfchk` accepts, so a file we load is one that standard tools also load, and every
rejection names file, line, section and reason.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

from servostudio.od.datatypes import DataType
from servostudio.od.eds_values import ValueSyntaxError, parse_integer, parse_number, parse_value
from servostudio.od.ini import IniEntry, IniFile, IniSection, parse_ini, read_ini
from servostudio.od.model import (
    Access,
    DictionaryError,
    DictObject,
    ObjectDictionary,
    ObjectKind,
    Variable,
)
from servostudio.od.props import apply_props

_OBJECT_SECTION = re.compile(r"^[0-9A-F]{4}$", re.IGNORECASE)
_SUB_SECTION = re.compile(r"^(?P<index>[0-9A-F]{4})sub(?P<sub>[0-9A-F]{1,2})$", re.IGNORECASE)
_COMPACT_SECTION = re.compile(r"^(?P<index>[0-9A-F]{4})(?P<kind>Name|Value)$", re.IGNORECASE)
_LOOKS_LIKE_OBJECT = re.compile(r"^[0-9A-F]{4}", re.IGNORECASE)

_OBJECT_LISTS = ("MandatoryObjects", "OptionalObjects", "ManufacturerObjects")
_MANDATORY = (0x1000, 0x1001, 0x1018)
_OBJECT_KEYS = frozenset(
    key.lower()
    for key in (
        "ParameterName",
        "ObjectType",
        "DataType",
        "AccessType",
        "DefaultValue",
        "PDOMapping",
        "LowLimit",
        "HighLimit",
        "SubNumber",
        "CompactSubObj",
        "ObjFlags",
        "ParameterValue",
        "Denotation",
        "UploadFile",
        "DownloadFile",
        "ParamRefd",
    )
)
_OBJECT_TYPES = {0x2: ObjectKind.VAR, 0x7: ObjectKind.VAR, 0x8: ObjectKind.ARRAY, 0x9: ObjectKind.RECORD}
NODE_IDS = range(1, 128)
#: a value read from an EDS: (value without its ``$NODEID`` term, uses ``$NODEID``, the text as written)
_EdsValue = tuple[int | float | str | bytes | None, bool, str | None]


@dataclass(frozen=True)
class DeviceInfo:
    product_name: str
    vendor_id: int
    product_code: int
    revision: int


def load_dictionary(eds_path: Path, props_path: Path | None = None) -> ObjectDictionary:
    """Read an EDS and its `.props` (default: same name with suffix .props, when that file exists).

    The device key is the EDS file name without suffix, lower-cased.
    """
    eds_path = Path(eds_path)
    if props_path is None:
        candidate = eds_path.with_suffix(".props")
        props_path = candidate if candidate.exists() else None
    reader = _EdsReader(read_ini(eds_path))
    objects = reader.objects()
    info = reader.device_info(objects[0x1018])
    if props_path is not None:
        objects = apply_props(read_ini(Path(props_path)), objects)
    return _dictionary(eds_path, info, objects)


def parse_dictionary(text: str, name: str) -> ObjectDictionary:
    """Read an EDS or DCF from its text (an upload); ``name`` is the file's name as the user knows it, and is the
    only file name its errors give (no server path)."""
    source = Path(name)
    reader = _EdsReader(parse_ini(text, source))
    objects = reader.objects()
    return _dictionary(source, reader.device_info(objects[0x1018]), objects)


def _dictionary(source: Path, info: DeviceInfo, objects: dict[int, DictObject]) -> ObjectDictionary:
    return ObjectDictionary(
        device=source.stem.lower(),
        product_name=info.product_name,
        vendor_id=info.vendor_id,
        product_code=info.product_code,
        revision=info.revision,
        source=source,
        objects=list(objects.values()),
    )


class _EdsReader:
    def __init__(self, ini: IniFile) -> None:
        self.ini = ini

    def error(self, section: IniSection | str, line: int, reason: str) -> DictionaryError:
        name = section if isinstance(section, str) else section.name
        return DictionaryError(self.ini.path, line, name, reason)

    # --- [DeviceInfo] -------------------------------------------------------------------------------------------

    def device_info(self, identity: DictObject) -> DeviceInfo:
        section = self.ini.section("DeviceInfo")
        if section is None:
            raise self.error("DeviceInfo", 1, "section [DeviceInfo] is missing")
        return DeviceInfo(
            product_name=section.get("ProductName") or self.ini.path.stem,
            vendor_id=self._identity_number(section, "VendorNumber", identity, 1),
            product_code=self._identity_number(section, "ProductNumber", identity, 2),
            revision=self._identity_number(section, "RevisionNumber", identity, 3),
        )

    def _identity_number(self, section: IniSection, key: str, identity: DictObject, sub: int) -> int:
        """A [DeviceInfo] number, else the 0x1018 default, else 0, as dcfchk reads it.

        CANopenNode writes ``VendorNumber=`` with no value: an empty key says as little as an absent one.  A given
        number must agree with a non-zero 0x1018 default; an absent one is not compared (dcfchk does the same)."""
        default = _integer_default(identity.subs.get(sub))
        if not section.get(key):
            return default
        value = self._integer(section, key)
        if default not in (0, value):
            reason = f"{key} {value:#x} differs from 0x1018,{sub} ({default:#x})"
            raise self.error(section, section.line_of(key), reason)
        return value

    # --- object lists -------------------------------------------------------------------------------------------

    def objects(self) -> dict[int, DictObject]:
        listed = self._listed_indices()
        self._check_sections_are_listed(listed)
        return {index: self._object(index) for index in sorted(listed)}

    def _listed_indices(self) -> dict[int, str]:
        listed: dict[int, str] = {}
        for list_name in _OBJECT_LISTS:
            section = self.ini.section(list_name)
            if section is None:
                if list_name == "MandatoryObjects":
                    raise self.error(list_name, 1, "section [MandatoryObjects] is missing")
                continue
            for index, line in self._read_list(section):
                if index in listed:
                    raise self.error(section, line, f"object 0x{index:04X} is already listed in [{listed[index]}]")
                self._check_list_range(section, line, index)
                if self.ini.section(f"{index:04X}") is None:
                    raise self.error(section, line, f"listed object 0x{index:04X} has no section [{index:04X}]")
                listed[index] = section.name
        mandatory = self.ini.known_section("MandatoryObjects")
        for index in _MANDATORY:
            if listed.get(index, "").lower() != "mandatoryobjects":
                raise self.error(mandatory, mandatory.line, f"mandatory object 0x{index:04X} is not listed")
        return listed

    def _read_list(self, section: IniSection) -> list[tuple[int, int]]:
        count = self._integer(section, "SupportedObjects")
        entries = []
        for listed in section:
            if listed.key.lower() == "supportedobjects":
                continue
            if not listed.key.isdigit() or not 1 <= int(listed.key) <= count:
                raise self.error(section, listed.line, f"unexpected entry {listed.key!r} (SupportedObjects={count})")
        for number in range(1, count + 1):
            entry = section.entry(str(number))
            if entry is None or not entry.value:
                state = "missing" if entry is None else "empty"
                line = section.line_of("SupportedObjects") if entry is None else entry.line
                raise self.error(section, line, f"entry {number} is {state}")
            try:
                index = parse_integer(entry.value)
            except ValueSyntaxError as exc:
                raise self.error(section, entry.line, str(exc)) from None
            if not 0x1000 <= index <= 0xFFFF:
                raise self.error(section, entry.line, f"0x{index:X} is not an object index (0x1000-0xFFFF)")
            entries.append((index, entry.line))
        return entries

    def _check_list_range(self, section: IniSection, line: int, index: int) -> None:
        name = section.name.lower()
        manufacturer = 0x2000 <= index <= 0x5FFF
        if name == "mandatoryobjects" and index not in _MANDATORY:
            raise self.error(section, line, f"object 0x{index:04X} is not a mandatory object")
        if name == "optionalobjects" and manufacturer:
            raise self.error(section, line, f"object 0x{index:04X} is manufacturer-specific")
        if name == "manufacturerobjects" and not manufacturer:
            raise self.error(section, line, f"object 0x{index:04X} is not manufacturer-specific (0x2000-0x5FFF)")

    def _check_sections_are_listed(self, listed: dict[int, str]) -> None:
        for section in self.ini:
            name = section.name
            if _OBJECT_SECTION.match(name):
                if int(name, 16) not in listed:
                    raise self.error(section, section.line, "object section is not listed in any object list")
            elif match := (_SUB_SECTION.match(name) or _COMPACT_SECTION.match(name)):
                self._check_parent(section, match["index"], listed, "sub" if _SUB_SECTION.match(name) else "compact")
            elif _LOOKS_LIKE_OBJECT.match(name):
                raise self.error(section, section.line, "malformed object section name")

    def _check_parent(self, section: IniSection, index_text: str, listed: dict[int, str], kind: str) -> None:
        """A [xxxxsubN] section needs a parent with SubNumber, an [xxxxName]/[xxxxValue] one with CompactSubObj."""
        if int(index_text, 16) not in listed:
            raise self.error(section, section.line, f"object [{index_text}] is not defined")
        parent = self.ini.known_section(index_text)
        key = "SubNumber" if kind == "sub" else "CompactSubObj"
        if not parent.get(key):
            raise self.error(section, section.line, f"object [{index_text}] has no {key}")

    # --- objects ------------------------------------------------------------------------------------------------

    def _object(self, index: int) -> DictObject:
        section = self.ini.known_section(f"{index:04X}")
        self._check_keys(section)
        name = self._name(section)
        object_type = self._integer(section, "ObjectType", 0x7)
        kind = _OBJECT_TYPES.get(object_type)
        if kind is None:
            raise self.error(section, section.line_of("ObjectType"), f"unsupported ObjectType 0x{object_type:X}")
        sub_number = self._integer(section, "SubNumber", 0)
        compact = self._integer(section, "CompactSubObj", 0)
        if kind is ObjectKind.VAR:
            for key in ("SubNumber", "CompactSubObj"):
                if self._integer(section, key, 0):
                    raise self.error(section, section.line_of(key), f"{key} is not allowed for a VAR")
            subs = {0: self._variable(section, index, 0, name, domain_object=object_type == 0x2)}
        elif sub_number and compact:
            raise self.error(section, section.line, "SubNumber and CompactSubObj are both given")
        elif sub_number:
            subs = self._explicit_subs(section, index, name, sub_number)
        elif compact:
            subs = self._compact_subs(section, index, name, compact)
        else:
            raise self.error(section, section.line, f"{kind.value} needs SubNumber or CompactSubObj")
        return DictObject(index=index, name=name, kind=kind, group="", subs=subs)

    def _explicit_subs(self, section: IniSection, index: int, name: str, sub_number: int) -> dict[int, Variable]:
        if section.get("AccessType"):
            raise self.error(section, section.line_of("AccessType"), "AccessType is not allowed on an ARRAY/RECORD")
        subs = {}
        for sub in range(0x100):
            sub_section = self.ini.section(f"{index:04X}sub{sub:X}")
            if sub_section is not None:
                self._check_keys(sub_section)
                subs[sub] = self._variable(sub_section, index, sub, name)
        if len(subs) != sub_number:
            raise self.error(
                section, section.line_of("SubNumber"), f"SubNumber={sub_number} but {len(subs)} sub-sections exist"
            )
        if 0 not in subs:
            raise self.error(section, section.line_of("SubNumber"), f"[{index:04X}sub0] is missing")
        if subs[0].data_type is not DataType.UNSIGNED8:
            sub0 = self.ini.known_section(f"{index:04X}sub0")
            raise self.error(sub0, sub0.line_of("DataType"), "sub-index 0 must be UNSIGNED8")
        return subs

    def _compact_subs(self, section: IniSection, index: int, name: str, count: int) -> dict[int, Variable]:
        if not 1 <= count <= 0xFE:
            raise self.error(section, section.line_of("CompactSubObj"), f"CompactSubObj={count} is not 1..254")
        names = self._compact_names(index, count)
        subs = {
            0: Variable(
                index=index,
                subindex=0,
                name="NrOfObjects",
                data_type=DataType.UNSIGNED8,
                access=Access.RO,
                default=count,
                default_expr=str(count),
                parent_name=name,
            )
        }
        template = self._variable(section, index, 1, name)
        configured = self._compact_values(index, count, template)
        for sub in range(1, count + 1):
            value, uses_node_id, text = configured.get(sub, (None, False, None))
            subs[sub] = replace(
                template,
                subindex=sub,
                name=names.get(sub, f"{name}{sub}"),
                parameter_value=value,
                parameter_expr=text,
                parameter_uses_node_id=uses_node_id,
            )
        return subs

    def _compact_names(self, index: int, count: int) -> dict[int, str]:
        section = self.ini.section(f"{index:04X}Name")
        return {} if section is None else {sub: entry.value for sub, entry in self._compact_entries(section, count)}

    def _compact_values(self, index: int, count: int, template: Variable) -> dict[int, _EdsValue]:
        """A DCF's ``[xxxxValue]`` section: the configured value of each compact sub-index, checked like any
        ParameterValue (type, limits, ``$NODEID``)."""
        section = self.ini.section(f"{index:04X}Value")
        if section is None:
            return {}
        low, high = template.low, template.high
        entries = self._compact_entries(section, count)
        return {sub: self._default(section, template.data_type, low, high, entry.key) for sub, entry in entries}

    def _compact_entries(self, section: IniSection, count: int) -> list[tuple[int, IniEntry]]:
        """The numbered entries of a ``[xxxxName]`` / ``[xxxxValue]`` section, which NrOfEntries must count."""
        entries = []
        for entry in section:
            if entry.key.lower() == "nrofentries":
                continue
            if not entry.key.isdigit() or not 1 <= int(entry.key) <= count:
                raise self.error(section, entry.line, f"sub-index {entry.key!r} is not 1..{count}")
            entries.append((int(entry.key), entry))
        declared = self._integer(section, "NrOfEntries")
        if declared != len(entries):
            raise self.error(
                section, section.line_of("NrOfEntries"), f"NrOfEntries={declared} but {len(entries)} entries"
            )
        return entries

    # --- one entry ----------------------------------------------------------------------------------------------

    def _variable(
        self, section: IniSection, index: int, sub: int, parent_name: str, domain_object: bool = False
    ) -> Variable:
        name = self._name(section)
        data_type = self._data_type(section, default=DataType.DOMAIN if domain_object else None)
        access = self._access(section, default=Access.RW if domain_object else None)
        pdo = self._integer(section, "PDOMapping", 0)
        if pdo not in (0, 1):
            raise self.error(section, section.line_of("PDOMapping"), f"PDOMapping must be 0 or 1, not {pdo}")
        low = self._limit(section, "LowLimit", data_type)
        high = self._limit(section, "HighLimit", data_type)
        if low is not None and high is not None and low > high:
            raise self.error(section, section.line_of("LowLimit"), f"LowLimit {low} is above HighLimit {high}")
        default, uses_node_id, expr = self._default(section, data_type, low, high, "DefaultValue")
        parameter, parameter_uses_node_id, parameter_expr = self._default(
            section, data_type, low, high, "ParameterValue"
        )
        return Variable(
            index=index,
            subindex=sub,
            name=name,
            data_type=data_type,
            access=access,
            pdo_mappable=bool(pdo),
            low=low,
            high=high,
            default=default,
            default_expr=expr,
            parent_name=parent_name,
            default_uses_node_id=uses_node_id,
            parameter_value=parameter,
            parameter_expr=parameter_expr,
            parameter_uses_node_id=parameter_uses_node_id,
        )

    def _name(self, section: IniSection) -> str:
        name = section.get("ParameterName")
        if not name:
            raise self._absent(section, "ParameterName")
        return name

    def _absent(self, section: IniSection, key: str) -> DictionaryError:
        """A required key without a value: "missing" when the key is not there, "empty" when it is written as
        ``key=`` (a generator's placeholder), so the reader knows whether to add the line or fill it in."""
        state = "empty" if key in section else "missing"
        return self.error(section, section.line_of(key), f"{key} is {state}")

    def _check_keys(self, section: IniSection) -> None:
        for entry in section:
            if entry.key.lower() not in _OBJECT_KEYS:
                raise self.error(section, entry.line, f"unknown key {entry.key!r}")

    def _data_type(self, section: IniSection, default: DataType | None) -> DataType:
        text = section.get("DataType")
        if not text:
            if default is None:
                raise self._absent(section, "DataType")
            return default
        code = self._integer(section, "DataType")
        try:
            return DataType(code)
        except ValueError:
            raise self.error(section, section.line_of("DataType"), f"unknown data type 0x{code:04X}") from None

    def _access(self, section: IniSection, default: Access | None) -> Access:
        text = section.get("AccessType")
        if not text:
            if default is None:
                raise self._absent(section, "AccessType")
            return default
        try:
            return Access(text.lower())
        except ValueError:
            choices = "|".join(a.value for a in Access)
            raise self.error(section, section.line_of("AccessType"), f"AccessType {text!r} is not {choices}") from None

    def _limit(self, section: IniSection, key: str, data_type: DataType) -> int | float | None:
        text = section.get(key)
        if not text:
            return None
        if not data_type.is_numeric:
            raise self.error(section, section.line_of(key), f"{key} is not allowed for {data_type.name}")
        value = self._number(section, key, text, data_type, allow_node_id=False)[0]
        self._check_type_range(section, key, data_type, value)
        return value

    def _default(
        self, section: IniSection, data_type: DataType, low: int | float | None, high: int | float | None, key: str
    ) -> _EdsValue:
        """Read DefaultValue (or a DCF's ParameterValue, or one entry of ``[xxxxValue]``): syntax, type range,
        limits, for node IDs 1 and 127.  Returns (value without its ``$NODEID`` term, uses ``$NODEID``, the text)."""
        text = section.get(key)
        if text is None or (text == "" and not (data_type.is_text or data_type.is_binary)):
            return None, False, None
        if not (data_type.is_numeric or data_type.is_time):
            return self._value(section, key, text, data_type), False, text
        value, uses_node_id = self._number(section, key, text, data_type, allow_node_id=data_type.is_integer)
        candidates = [value + node for node in (NODE_IDS[0], NODE_IDS[-1])] if uses_node_id else [value]
        for candidate in candidates:
            self._check_type_range(section, key, data_type, candidate)
            if (low is not None and candidate < low) or (high is not None and candidate > high):
                raise self.error(section, section.line_of(key), f"{key} {text} is outside the limits {low}..{high}")
        return value, uses_node_id, text

    def _value(self, section: IniSection, key: str, text: str, data_type: DataType) -> int | float | str | bytes:
        try:
            return parse_value(data_type, text)[0]
        except ValueSyntaxError as exc:
            raise self.error(section, section.line_of(key), f"{key}: {exc}") from None

    def _number(
        self, section: IniSection, key: str, text: str, data_type: DataType, allow_node_id: bool
    ) -> tuple[int | float, bool]:
        try:
            return parse_number(data_type, text, allow_node_id)
        except ValueSyntaxError as exc:
            raise self.error(section, section.line_of(key), f"{key}: {exc}") from None

    def _check_type_range(self, section: IniSection, key: str, data_type: DataType, value: int | float) -> None:
        if data_type.is_float:
            return
        low, high = data_type.integer_range
        if not low <= value <= high:
            raise self.error(
                section, section.line_of(key), f"{key} {value} is outside the {data_type.name} range {low}..{high}"
            )

    def _integer(self, section: IniSection, key: str, default: int | None = None) -> int:
        text = section.get(key)
        if not text:
            if default is None:
                raise self._absent(section, key)
            return default
        try:
            return parse_integer(text)
        except ValueSyntaxError as exc:
            raise self.error(section, section.line_of(key), f"{key}: {exc}") from None


def _integer_default(var: Variable | None) -> int:
    """The node-independent integer default of an entry, 0 when it has none (an identity entry without a value)."""
    return var.default if var is not None and isinstance(var.default, int) else 0
