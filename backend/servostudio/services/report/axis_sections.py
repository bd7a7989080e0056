"""The report's sections about an axis as a whole: the drive, the motor, the parameters that differ from the
dictionary defaults, the settings files with their checksums, and who did what when."""

from __future__ import annotations

from collections import Counter
from typing import Any

from servostudio.services.projects import ParameterRow
from servostudio.services.projects.parameter_values import display
from servostudio.services.report import results
from servostudio.services.report.collect import AxisRecord, FileSum
from servostudio.services.report.markup import absent, facts, note, shown, table, text

IDENTITY_NUMBERS = (("vendor_id", "Vendor ID"), ("product_code", "Product code"), ("revision", "Revision number"),
                    ("serial_number", "Serial number"))  # fmt: skip
#: audit entries of one second, one user and one axis are one change (a backup writes hundreds at once)
HISTORY_ROWS = 30


def drive(record: AxisRecord) -> str:
    """Identity from the dictionary the axis names, and what a saved capture recorded of the drive itself."""
    axis, dictionary = record.axis, record.dictionary
    rows = [
        ("Device", text(axis.device) + (f" — {text(dictionary.product_name)}" if dictionary else "")),
        ("Bus, node", f"{text(axis.bus)} ({text(record.bus_interface)}), node {axis.node_id}"),
    ]
    if dictionary is not None:
        numbers = (dictionary.vendor_id, dictionary.product_code, dictionary.revision)
        rows.append(
            ("Dictionary identity", text("vendor 0x{:08X}, product 0x{:08X}, revision 0x{:08X}".format(*numbers)))
        )
    else:
        rows.append(("Dictionary identity", text(f"the EDS library has no dictionary '{axis.device}'")))
    if axis.description:
        rows.append(("Description", text(axis.description)))
    return facts(rows) + _recorded_identity(record)


def _recorded_identity(record: AxisRecord) -> str:
    identity = record.identity
    if identity is None:
        return absent("Firmware and serial number not recorded in the project: no saved capture of this axis names "
                      "the drive it came from.")  # fmt: skip
    rows = [(name, _hex(identity.get(key))) for key, name in IDENTITY_NUMBERS]
    rows.append(("Firmware (software version)", shown(identity.get("software_version") or None)))
    rows.append(("Product name", shown(identity.get("product_name") or None)))
    return note(f"As the drive identified itself in the {record.identity_source}:") + facts(rows)


def _hex(value: object) -> str:
    return text(f"0x{value:08X}") if isinstance(value, int) and not isinstance(value, bool) else shown(value)


def motor(record: AxisRecord) -> str:
    chosen = record.motor
    parts = []
    if chosen is not None:
        data = [(key, shown(value)) for key, value in chosen.motor_data.items()]
        described = [("Catalog motor", text(chosen.reference)), ("Description", shown(chosen.description or None))]
        parts.append(facts([*described, ("Source", shown(chosen.source or None)), *data]))
    elif record.axis.motor:
        parts.append(absent(f"Motor '{record.axis.motor}' was chosen, but the motor catalog no longer has it."))
    else:
        parts.append(absent("No catalog motor chosen for this axis."))
    if record.motor_rows:
        parts.append(note("Motor data the project sets:") + _parameter_table(record.motor_rows))
    else:
        parts.append(absent("The project sets no motor data: every motor object has its dictionary default."))
    return "".join(parts)


def parameters(record: AxisRecord) -> str:
    if not record.differing:
        return absent("Every parameter saved in the drive files has its dictionary default.")
    count = len(record.differing)
    differ = "parameter differs" if count == 1 else "parameters differ"
    return note(f"{count} {differ} from the dictionary defaults.") + _parameter_table(record.differing)


def _parameter_table(rows: list[ParameterRow]) -> str:
    cells = [
        (
            text(f"0x{row.variable.index:04X},{row.variable.subindex}"),
            text(row.variable.label),
            shown(display(row.variable, row.value), row.variable.unit),
            shown(display(row.variable, row.default), row.variable.unit),
            shown(row.file),
        )
        for row in rows
    ]
    return table(("object", "name", "project value", "default", "file"), cells, "parameters")


def files(record: AxisRecord) -> str:
    return checksums(record.files, "The axis has no settings files.")


def checksums(sums: list[FileSum], empty: str) -> str:
    if not sums:
        return absent(empty)
    rows = [(text(item.path), text(item.size), f"<code>{text(item.sha256)}</code>", shown(item.header or None))
            for item in sums]  # fmt: skip
    return table(("file", "bytes", "SHA-256", "first comment (a backup names its node and time)"), rows, "files")


def history(record: AxisRecord, audit_available: bool) -> str:
    return _saved_records(record) + audit(record.history, audit_available)


def _saved_records(record: AxisRecord) -> str:
    rows = [(shown(item.get("saved_at")), text(results.label(item)), shown(item.get("status")),
             text(results.who(item))) for item in record.procedures]  # fmt: skip
    rows += [(shown(item.get("time")), text(f"frequency response '{item.get('name')}'"), text(_state(item)),
              text(results.who(item))) for item in record.frequency]  # fmt: skip
    if not rows:
        return absent("No procedure result or frequency response is saved under this axis.")
    rows.sort(key=lambda row: row[0], reverse=True)
    return note("Saved results:") + table(("time (UTC)", "what", "status", "user"), rows)


def _state(response: dict[str, Any]) -> str:
    if response.get("error"):
        return "damaged"
    return "aborted" if response.get("aborted") else "done"


def audit(entries: list[dict[str, Any]], available: bool) -> str:
    """The audit log's changes: one row per second, user and change."""
    if not available:
        return absent("No audit log at hand (it is the server's, not the project's, and reading it needs the Expert "
                      "level): who changed the project's settings is not shown.")  # fmt: skip
    if not entries:
        return absent("The audit log records no change here.")
    changes = Counter((str(entry.get("time", ""))[:19], str(entry.get("user", "")), _what(entry)) for entry in entries)
    rows = [(text(stamp), text(user), text(f"{what} ({count} entries)" if count > 1 else what))
            for (stamp, user, what), count in list(changes.items())[:HISTORY_ROWS]]  # fmt: skip
    users = Counter(str(entry.get("user", "")) for entry in entries)
    summary = ", ".join(f"{user} ({count})" for user, count in users.most_common())
    return note(f"Changes of the project's settings in the audit log, newest first; by {summary}:") + table(
        ("time (UTC)", "user", "change"), rows
    )


def _what(entry: dict[str, Any]) -> str:
    if entry.get("detail"):
        return str(entry["detail"])
    axis = entry.get("project_axis")
    return f"values of axis {axis} changed" if axis else str(entry.get("action", "change"))
