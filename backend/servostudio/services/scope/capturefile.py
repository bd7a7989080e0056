"""The capture file format: CSV data any tool reads, plus a JSON sidecar with what the CSV cannot carry exactly.

CSV (``NAME.csv``, UTF-8): ``# key: value`` comment lines first (period, samples, trigger, pre-trigger, units,
drive, node, bus, captured, source), then the header ``time_s,"0x606C,0",…`` (objects spelled ``0x606C,0``, so
quoted as CSV quotes a field with a comma), then one row per sample: the time in seconds (0 = the trigger sample,
written exactly from integer nanoseconds) and each channel's physical value (``raw × scale + offset``). The units
line is a CSV row aligned with the header.

JSON sidecar (``NAME.json``): format and version, the definition, the channels with unit, type, scale and offset,
the period in ns, the samples, the trigger sample, the drive's identity, the time of capture. Re-opening checks the
two files against each other row by row, so a damaged file is refused with its name and line.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Iterator, Mapping
from dataclasses import asdict
from decimal import Decimal, InvalidOperation
from typing import Any

from servostudio.errors import InvalidInput
from servostudio.services.scope.capture import Capture, ChannelInfo, DriveIdentity, Number
from servostudio.services.scope.definition import CaptureDefinition, fixed_point_text

FORMAT, VERSION = "servostudio-capture", 1
TIME_COLUMN = "time_s"
NS_PER_S = 10**9


class CaptureFileError(InvalidInput):
    """A capture file that is damaged or not a capture; the message names the file and the line."""


# ---- writing --------------------------------------------------------------------------------------------------


def capture_csv(capture: Capture) -> str:
    """The CSV text of a capture."""
    out = io.StringIO()
    writer = csv_head(out, _comments(capture), capture.channels)
    columns = [capture.physical(channel) for channel in range(len(capture.channels))]
    for sample in range(capture.samples):
        writer.writerow([seconds_text(capture.time_ns(sample)), *(value_text(column[sample]) for column in columns)])
    return out.getvalue()


def csv_head(out: io.StringIO, comments: list[tuple[str, str]], channels: tuple[ChannelInfo, ...]) -> Any:
    """The comment lines and the header row, written; the writer of the data rows (the roll's CSV shares it)."""
    writer = csv.writer(out, lineterminator="\n")
    for key, value in comments:
        out.write(f"# {key}: {value}\n")
    writer.writerow([TIME_COLUMN, *(channel.key for channel in channels)])
    return writer


def units_text(channels: tuple[ChannelInfo, ...]) -> str:
    """The ``units`` comment: a CSV row aligned with the header (``s`` for the time)."""
    units = io.StringIO()
    csv.writer(units, lineterminator="").writerow(["s", *(channel.unit for channel in channels)])
    return units.getvalue()


def _comments(capture: Capture) -> list[tuple[str, str]]:
    definition = capture.definition
    return [
        ("period", f"{microseconds_text(capture.period_ns)} us"),
        ("samples", str(capture.samples)),
        ("trigger", capture.trigger),
        ("pre-trigger", f"{definition.pre_trigger_pct:g} % ({capture.trigger_index} samples)"),
        ("units", units_text(capture.channels)),
        ("drive", capture.drive.describe()),
        ("node", str(capture.drive.node)),
        ("bus", capture.drive.bus),
        ("captured", capture.captured_at),
        ("source", capture.source),
    ]


def capture_sidecar(capture: Capture, data_name: str) -> str:
    """The JSON sidecar of a capture whose CSV is named ``data_name``."""
    sidecar = {
        "format": FORMAT,
        "version": VERSION,
        "data": data_name,
        "source": capture.source,
        "captured_at": capture.captured_at,
        "drive": asdict(capture.drive),
        "definition": capture.definition.as_dict(),
        "trigger": capture.trigger,
        "period_ns": capture.period_ns,
        "samples": capture.samples,
        "trigger_index": capture.trigger_index,
        "channels": [asdict(channel) for channel in capture.channels],
        "alignment_ns": capture.alignment_ns,
    }
    return json.dumps(sidecar, indent=2, ensure_ascii=False) + "\n"


def seconds_text(nanoseconds: int) -> str:
    """Integer nanoseconds as exact decimal seconds: -20000000 → ``-0.02``, 250000 → ``0.00025``."""
    return fixed_point_text(nanoseconds, 9)


def microseconds_text(nanoseconds: int) -> str:
    """Integer nanoseconds as exact decimal microseconds: 250000 → ``250``."""
    return fixed_point_text(nanoseconds, 3)


def value_text(value: Number) -> str:
    return str(value) if isinstance(value, int) else repr(value)


# ---- reading --------------------------------------------------------------------------------------------------


def parse_capture(csv_text: str, sidecar_text: str, csv_label: str, sidecar_label: str) -> Capture:
    """The capture two files hold; ``CaptureFileError`` names the file and line of the first problem."""
    header = read_sidecar(sidecar_text, sidecar_label)
    columns = _read_rows(csv_text, csv_label, header)
    return Capture(
        definition=header.definition,
        channels=header.channels,
        period_ns=header.period_ns,
        trigger_index=header.trigger_index,
        trigger=header.trigger,
        columns=columns,
        drive=header.drive,
        captured_at=header.captured_at,
        source=header.source,
        alignment_ns=header.alignment_ns,
    )


def read_sidecar(text: str, label: str) -> Sidecar:
    """What a sidecar says about its capture, checked (the CSV is read only when the capture is opened)."""
    return Sidecar.of(_sidecar_fields(text, label), text, label)


def _sidecar_fields(text: str, label: str) -> dict[str, Any]:
    try:
        fields = json.loads(text)
    except json.JSONDecodeError as error:
        raise CaptureFileError(f"{label}:{error.lineno}: not JSON: {error.msg}") from None
    if not isinstance(fields, dict) or fields.get("format") != FORMAT:
        raise CaptureFileError(f"{label}:1: not a capture sidecar (format {FORMAT!r} expected)")
    if fields.get("version") != VERSION:
        raise CaptureFileError(f"{label}:{_line_of(text, 'version')}: capture format version {VERSION} expected")
    return fields


def _line_of(text: str, key: str) -> int:
    """The line where the sidecar names ``key`` (1 when it does not: the object that lacks it starts there)."""
    marker = f'"{key}"'
    position = text.find(marker)
    return text.count("\n", 0, position) + 1 if position >= 0 else 1


class Sidecar:
    """What the sidecar says, each field checked where it is read."""

    def __init__(self, **fields: Any) -> None:
        self.__dict__.update(fields)

    definition: CaptureDefinition
    channels: tuple[ChannelInfo, ...]
    period_ns: int
    samples: int
    trigger_index: int
    trigger: str
    drive: DriveIdentity
    captured_at: str
    source: str
    alignment_ns: int | None

    @classmethod
    def of(cls, fields: Mapping[str, Any], text: str, label: str) -> Sidecar:
        def field(key: str, kind: type, build: Any = None) -> Any:
            where = f"{label}:{_line_of(text, key)}"
            value = fields.get(key)
            if not isinstance(value, kind) or isinstance(value, bool):
                raise CaptureFileError(f"{where}: '{key}' is missing or not {kind.__name__}")
            try:
                return value if build is None else build(value)
            except (TypeError, ValueError, KeyError) as error:
                raise CaptureFileError(f"{where}: '{key}' is not valid: {error}") from None

        header = cls(
            definition=field("definition", dict, CaptureDefinition.from_dict),
            channels=field("channels", list, lambda items: tuple(ChannelInfo(**item) for item in items)),
            period_ns=field("period_ns", int),
            samples=field("samples", int),
            trigger_index=field("trigger_index", int),
            trigger=field("trigger", str),
            drive=field("drive", dict, lambda values: DriveIdentity(**values)),
            captured_at=field("captured_at", str),
            source=field("source", str),
            alignment_ns=_alignment(fields, text, label),
        )
        header._check(text, label)
        return header

    def _check(self, text: str, label: str) -> None:
        for channel in self.channels:
            try:
                channel.type  # noqa: B018 -- the type name must be one the format knows
            except KeyError:
                raise CaptureFileError(
                    f"{label}:{_line_of(text, 'channels')}: unknown data type {channel.data_type!r}"
                ) from None
        if not self.channels or self.period_ns <= 0 or not 0 <= self.trigger_index < max(self.samples, 1):
            raise CaptureFileError(f"{label}:1: channels, period or trigger sample out of range")


def _alignment(fields: Mapping[str, Any], text: str, label: str) -> int | None:
    """The samples' largest distance from their instants (ns; absent or null: not stated, as in older files)."""
    value = fields.get("alignment_ns")
    if value is None:
        return None
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise CaptureFileError(f"{label}:{_line_of(text, 'alignment_ns')}: 'alignment_ns' is not a count of ns")
    return value


def _read_rows(text: str, label: str, header: Sidecar) -> tuple[tuple[Number, ...], ...]:
    lines = _data_lines(text, label)
    expected = [TIME_COLUMN, *(channel.key for channel in header.channels)]
    number, names = next(lines, (1, []))
    if names != expected:
        raise CaptureFileError(f"{label}:{number}: header {names} does not match the sidecar's {expected}")
    columns: list[list[Number]] = [[] for _ in header.channels]
    for number, row in lines:
        _add_row(columns, row, f"{label}:{number}", header, len(columns[0]))
    if len(columns[0]) != header.samples:
        raise CaptureFileError(f"{label}:{number}: {len(columns[0])} samples, the sidecar says {header.samples}")
    return tuple(tuple(column) for column in columns)


def _data_lines(text: str, label: str) -> Iterator[tuple[int, list[str]]]:
    """(line number, fields) of the header and the rows, after the ``# key: value`` comments."""
    lines = text.splitlines()
    start = next((number for number, line in enumerate(lines) if not line.startswith("#")), len(lines))
    yield from enumerate(csv.reader(lines[start:]), start + 1)


def _add_row(columns: list[list[Number]], row: list[str], where: str, header: Sidecar, sample: int) -> None:
    if len(row) != len(columns) + 1:
        raise CaptureFileError(f"{where}: {len(row)} fields, the header has {len(columns) + 1}")
    if sample >= header.samples:
        raise CaptureFileError(f"{where}: more rows than the {header.samples} samples the sidecar names")
    expected_ns = (sample - header.trigger_index) * header.period_ns
    if _nanoseconds(row[0], where) != expected_ns:
        raise CaptureFileError(f"{where}: time {row[0]} s, expected {seconds_text(expected_ns)} s for sample {sample}")
    for column, channel, text in zip(columns, header.channels, row[1:], strict=True):
        column.append(_raw(channel, text, where))


def _nanoseconds(text: str, where: str) -> int:
    try:
        value = Decimal(text) * NS_PER_S
    except InvalidOperation:
        raise CaptureFileError(f"{where}: time {text!r} is not a number") from None
    if value != value.to_integral_value():
        raise CaptureFileError(f"{where}: time {text!r} is not a whole number of nanoseconds")
    return int(value)


def _raw(channel: ChannelInfo, text: str, where: str) -> Number:
    """The raw value a physical one in the CSV stands for; refused when the drive could not have recorded it."""
    try:
        physical = float(text)
    except ValueError:
        raise CaptureFileError(f"{where}: {channel.key} value {text!r} is not a number") from None
    if not math.isfinite(physical):
        raise CaptureFileError(f"{where}: {channel.key} value {text} is not a finite number")
    raw = channel.raw_of(physical)
    low, high = channel.type.min_value, channel.type.max_value
    outside = low is not None and high is not None and not low <= raw <= high
    if outside or float(channel.physical(raw)) != physical:
        raise CaptureFileError(f"{where}: {channel.key} value {text} is no {channel.data_type} value of the channel")
    return raw
