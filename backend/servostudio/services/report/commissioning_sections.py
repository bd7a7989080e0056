"""The report's sections about commissioning an axis, from its saved results: phasing, the identified plant,
tuning (options, gains before → after), the verification steps and the frequency responses (Bode)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from servostudio.services.report import plots, results
from servostudio.services.report.collect import AxisRecord
from servostudio.services.report.markup import absent, facts, note, shown, table, text
from servostudio.services.report.results import Names

PLANT_KEYS = {
    "inertia_kgm2": "Inertia J [kg·m²]",
    "viscous_friction_nms_per_rad": "Viscous friction B [N·m·s/rad]",
    "coulomb_friction_nm": "Coulomb friction Tc [N·m]",
    "load_torque_nm": "Load torque Tg [N·m]",
    "residual": "Fit residual",
    "inertia_ratio": "Inertia ratio J / J motor",
    "inertia_as2_per_rad": "J / Kt [A·s²/rad] (per N·m/A)",
    "viscous_friction_as_per_rad": "B / Kt [A·s/rad] (per N·m/A)",
    "coulomb_friction_a": "Tc / Kt [A] (per N·m/A)",
    "load_torque_a": "Tg / Kt [A] (per N·m/A)",
}
STEP_METRICS = (("rise_time_s", "rise time 10→90 %", "s"), ("overshoot_pct", "overshoot", "%"),
                ("settling_time_s", "settling time ±5 %", "s"), ("bandwidth_hz", "−3 dB bandwidth", "Hz"))  # fmt: skip
MARKERS = (("bandwidth_hz", "bandwidth", "Hz"), ("gain_margin_db", "gain margin", "dB"),
           ("phase_margin_deg", "phase margin", "°"), ("resonance_hz", "resonance", "Hz"),
           ("antiresonance_hz", "anti-resonance", "Hz"))  # fmt: skip


def phasing(record: AxisRecord) -> str:
    saved = results.of(record.procedures, results.PHASING)
    finished = results.done(saved)
    if not finished:
        newest = f" (the newest saved run, {saved[0].get('file')}, ended {saved[0].get('status')})" if saved else ""
        return absent(f"Not phased from the tool yet: no completed auto-phasing or motor phasing is saved{newest}.")
    result, names = finished[0], Names(record.axis.device, record.dictionary)
    before = _mapping(result.get("before"))
    found = [key for key in result if key not in results.META]
    rows = [(text(names(key)), shown(before.get(key)), shown(result[key])) for key in found]
    head = _run_facts(result)
    return head + table(("value", "before", "found"), rows) + _commutation(result.get("verification"))


def _mapping(value: object) -> dict[str, Any]:
    """A nested object of a saved file, or nothing when the file holds something else there."""
    return value if isinstance(value, dict) else {}


def _commutation(check: object) -> str:
    if not isinstance(check, dict):
        return absent("No commutation check was saved with this result.")
    if check.get("skipped"):
        return absent(f"Commutation check skipped: {check['skipped']}")
    return note("Commutation check (torque per ampere with the offset found and shifted by ±45° el.):") + facts([
        ("torque per ampere / ideal", shown(check.get("torque_per_ampere_ratio"))),
        ("commutation error", shown(check.get("error_deg"), "° el.")),
        ("passed (≥ 0.98)", shown(check.get("passed"))),
        *([("reason", shown(check["reason"]))] if check.get("reason") else []),
    ])  # fmt: skip


def plant(record: AxisRecord) -> str:
    """Every identification side by side: the drive's auto-tuning, the tool's identification, the Bode fit."""
    sources = [(f"{results.label(item)}, {results.when(item)}", _identified(item))
               for item in results.done(results.of(record.procedures, ("auto_tuning", "identification")))]  # fmt: skip
    sources += [(f"Bode plant fit '{item.get('name')}', {item.get('time')}", item["plant_fit"])
                for item in record.frequency if isinstance(item.get("plant_fit"), dict)]  # fmt: skip
    if not sources:
        return absent("No identified plant: neither auto-tuning nor the tool's identification nor a plant "
                      "frequency response is saved for this axis.")  # fmt: skip
    keys = [key for key in PLANT_KEYS if any(values.get(key) is not None for _, values in sources)]
    rows = [(text(PLANT_KEYS[key]), *(shown(values.get(key)) for _, values in sources)) for key in keys]
    return table(("quantity", *(name for name, _ in sources)), rows, "plant")


def _identified(result: Mapping[str, Any]) -> dict[str, Any]:
    identified = result.get("identified")
    if not isinstance(identified, dict):
        return {}
    per_ampere = identified.get("per_ampere")
    return {**identified, **(per_ampere if isinstance(per_ampere, dict) else {})}


def tuning(record: AxisRecord) -> str:
    saved = results.of(record.procedures, results.TUNING)
    shown_runs = [_tuning_run(item, Names(record.axis.device, record.dictionary)) for item in _newest_each(saved)]
    if not shown_runs:
        return absent("Not tuned from the tool yet: no current-loop calculation, auto-tuning or identification "
                      "result is saved for this axis.")  # fmt: skip
    return "".join(shown_runs)


def _newest_each(saved: list[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The newest result of each procedure (newest first, as the store lists them)."""
    seen: dict[str, Mapping[str, Any]] = {}
    for item in saved:
        seen.setdefault(results.procedure(item), item)
    return list(seen.values())


def _tuning_run(result: Mapping[str, Any], names: Names) -> str:
    parts = [f"<h4>{text(results.label(result))}</h4>", _run_facts(result)]
    options = result.get("options")
    if isinstance(options, dict) and options:
        parts.append(note("Options:") + facts([(str(key), shown(value)) for key, value in options.items()]))
    for key, title in (("gains", "Gains"), ("limits", "Limits")):
        pair = result.get(key)
        if isinstance(pair, dict):
            parts.append(note(f"{title} before → after (raw values):") + _before_after(pair, names))
    return "".join(parts)


def _before_after(pair: Mapping[str, Any], names: Names) -> str:
    before = _mapping(pair.get("before"))
    after = _mapping(pair.get("after"))
    keys = list(dict.fromkeys([*before, *after]))
    rows = [(text(names(key)), shown(before.get(key)), shown(after.get(key)),
             "changed" if before.get(key) != after.get(key) else "") for key in keys]  # fmt: skip
    return table(("object", "before", "after", ""), rows, "gains")


def _run_facts(result: Mapping[str, Any]) -> str:
    rows = [("status", shown(result.get("status"))), ("when (UTC)", text(results.when(result))),
            ("user", text(results.who(result))), ("file", shown(result.get("file")))]  # fmt: skip
    return facts(rows)


def steps(record: AxisRecord, anchor: str) -> str:
    """The verification steps saved with auto-tuning or identification, plotted from their recordings."""
    verified = [item for item in results.done(results.of(record.procedures, ("auto_tuning", "identification")))
                if isinstance(item.get("verification"), dict)]  # fmt: skip
    if not verified:
        return absent("No step response saved: no auto-tuning or identification with a verification step.")
    return "".join(_verification(item, f"{anchor}-{number}") for number, item in enumerate(_newest_each(verified)))


def _verification(result: Mapping[str, Any], anchor: str) -> str:
    check = result["verification"]
    head = f"<h4>{text(results.label(result))}, {text(results.when(result))}</h4>"
    if check.get("skipped"):
        return head + absent(f"Verification skipped: {check['skipped']}")
    parts = [head]
    for key, title in (("speed_step", "Speed step"), ("position_step", "Position step")):
        step = check.get(key)
        if isinstance(step, dict):
            parts.append(_step(step, title, f"{anchor}-{key}"))
    return "".join(parts) if len(parts) > 1 else head + absent("The verification saved no step.")


def _step(step: Mapping[str, Any], title: str, anchor: str) -> str:
    metrics = facts([(name, shown(step.get(key), unit)) for key, name, unit in STEP_METRICS])
    capture = step.get("capture")
    plot = plots.step_plot(capture, anchor) if isinstance(capture, dict) else None
    shown_plot = plot or absent("The saved recording of this step cannot be plotted (no or damaged samples).")
    return f'<div class="step"><h5>{text(title)}</h5>{metrics}{shown_plot}</div>'


def bode(record: AxisRecord, anchor: str) -> str:
    saved = record.frequency
    if not saved:
        return absent("No frequency response (Bode) saved for this axis.")
    summary = table(("name", "loop", "time (UTC)", "user", "excitation", "markers", "state"),
                    [_bode_row(item) for item in saved], "bode")  # fmt: skip
    plotted = [plots.bode_plot(_loop(saved, loop), f"{anchor}-{loop}") for loop in ("plant", "closed", "open")]
    drawn = "".join(plot for plot in plotted if plot)
    return summary + (drawn or absent("None of the saved frequency responses has points to plot."))


def _loop(saved: list[dict[str, Any]], loop: str) -> list[dict[str, Any]]:
    return [item for item in saved if item.get("loop") == loop and not item.get("error")]


def _bode_row(item: Mapping[str, Any]) -> tuple[str, ...]:
    excitation = _mapping(item.get("excitation"))
    markers = _mapping(item.get("markers"))
    marked = "; ".join(f"{name} {shown(markers.get(key), unit)}" for key, name, unit in MARKERS
                       if markers.get(key) is not None)  # fmt: skip
    excited = ", ".join(f"{text(key)} {shown(value)}" for key, value in excitation.items())
    state = item.get("error") or (f"aborted: {item['aborted']}" if item.get("aborted") else "complete")
    return (shown(item.get("name")), shown(item.get("loop")), shown(item.get("time")), text(results.who(item)),
            excited or "—", marked or "—", text(state))  # fmt: skip
