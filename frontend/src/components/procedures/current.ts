/**
 * The parts of the current-loop page: the drive's values it needs (inductance, drive and motor currents, current
 * limits, I²t mode; per device, `CURRENT_ENTRIES`), the 'calc' options, the current limits with the manual's rule
 * and ranges, and the I²t protection with its mode (Fusing while commissioning) and the manual's timing formulas.
 */

import { projectAddress } from "../../client/api";
import { driveApi } from "../../client/drives";
import type { CurrentLoopOptions } from "../../client/procedures";
import { effect, h, state, untrack, type State } from "../../lib/dom";
import { formatNumber, parseNumber } from "../../lib/numbers";
import type { Dictionary, OdVariable } from "../../lib/od";
import { CURRENT_ENTRIES, currentLimits, i2tTimes, limitProblems, sig, type CurrentQuantity } from "../../lib/procedures";
import { errorText, messageView, type Message } from "../ui";
import type { ProceduresModel } from "./model";

const INDUCTANCE_VALUES = ["value:control_inductance", "value:motor_inductance"];

export interface CurrentValues {
  /** Physical values read from the drive (in the dictionary's unit), by quantity. */
  values: State<Partial<Record<CurrentQuantity, number>>>;
  variables: Partial<Record<CurrentQuantity, OdVariable>>;
  /** Their addresses (`0x340F,0`). */
  keys: Partial<Record<CurrentQuantity, string>>;
  error: State<string | null>;
  reload(): Promise<void>;
}

export function currentValues(model: ProceduresModel, dictionary: Dictionary): CurrentValues {
  const wanted = CURRENT_ENTRIES[dictionary.device] ?? {};
  const variables: Partial<Record<CurrentQuantity, OdVariable>> = {};
  for (const [quantity, [index, sub]] of Object.entries(wanted) as [CurrentQuantity, [number, number]][]) {
    const variable = dictionary.objects.find((object) => object.index === index)?.subs.find((candidate) => candidate.subindex === sub);
    if (variable) variables[quantity] = variable;
  }
  const quantities = Object.keys(variables) as CurrentQuantity[];
  const keys = Object.fromEntries(quantities.map((quantity) => [quantity, projectAddress(...wanted[quantity]!)]));
  const values = state<Partial<Record<CurrentQuantity, number>>>({});
  const error = state<string | null>(null);
  const reload = async () => {
    if (quantities.length === 0) return;
    try {
      const results = await driveApi.readKeys(model.where.bus, model.where.node, quantities.map((quantity) => keys[quantity]));
      const next: Partial<Record<CurrentQuantity, number>> = {};
      results.forEach((result, position) => {
        const physical = result.value?.physical;
        if (typeof physical === "number") next[quantities[position]] = physical;
      });
      values.val = next;
      error.val = null;
    } catch (failure) {
      error.val = errorText(failure);
    }
  };
  return { values, variables, keys, error, reload };
}

/** A value with its unit, or "—". */
function shown(current: CurrentValues, quantity: CurrentQuantity): string {
  const value = current.values.val[quantity];
  if (value === undefined) return "—";
  const unit = current.variables[quantity]?.unit ?? "";
  return `${formatNumber(value, 6)}${unit ? ` ${unit}` : ""}`;
}

/** The 'calc' inputs: the phase-to-phase inductance (motor + series inductors) and the current loop bandwidth. */
export function calcFields(current: CurrentValues): { element: HTMLElement; options(): Partial<CurrentLoopOptions>; provides(): string[] } {
  const inductance = state("");
  const regulator = state<"high" | "low">("high");
  // Prefilled with the drive's value once it was read, unless the user typed one.
  effect(() => {
    const value = current.values.val.inductance;
    if (value !== undefined && untrack(() => inductance.val) === "") inductance.val = formatNumber(value, 6);
  });
  const field = h("input", { "data-testid": "cl-inductance", inputmode: "decimal", style: { width: "100px" }, value: inductance,
    oninput: (event: Event) => (inductance.val = (event.target as HTMLInputElement).value) });
  const element = h("div", { class: "grid", style: { gridTemplateColumns: "auto 1fr", gap: "6px 12px", alignItems: "center" } },
    h("label", null, "Motor inductance, phase to phase [mH]"), h("span", null, field, h("span", { class: "muted" }, " motor plus external series inductors")),
    h("label", null, "Current loop bandwidth"),
    h("select", { "data-testid": "cl-regulator", value: regulator, onchange: (event: Event) => (regulator.val = (event.target as HTMLSelectElement).value as "high" | "low") },
      h("option", { value: "high" }, "High: motor current up to 900 Hz, high gains (default)"),
      h("option", { value: "low" }, "Low: filtered current measurement, less whistling, up to 400 Hz")),
    h("label", null, "Drive current (rating / rated)"),
    h("span", { "data-testid": "cl-drive-current" }, () => `${shown(current, "driveMax")} / ${shown(current, "driveRated")}`),
    h("span", { class: "muted", style: { gridColumn: "1 / -1" } },
      "'calc' computes the current loop gains (0x60F6) from the inductance and the drive's maximum current, and the current limits with them."));
  const options = (): Partial<CurrentLoopOptions> => {
    const text = inductance.rawVal.trim();
    if (text === "") return { inductance_mh: null, regulator: regulator.rawVal };
    const parsed = parseNumber(text);
    if (!parsed.ok) throw new Error(`Inductance: ${parsed.error}`);
    if (!(parsed.value > 0)) throw new Error(`Inductance: ${text} mH is not a positive inductance`);
    return { inductance_mh: parsed.value, regulator: regulator.rawVal };
  };
  // A typed inductance is written to the motor data before 'calc': the drive's 0 there no longer blocks Start.
  const provides = () => {
    const parsed = parseNumber(inductance.val.trim());
    return parsed.ok && parsed.value > 0 ? INDUCTANCE_VALUES : [];
  };
  return { element, options, provides };
}

/** The current limits now on the drive, what the manual's rule gives from the motor and drive currents, and the ranges. */
export function limitsFields(current: CurrentValues): HTMLElement {
  return h("div", { "data-testid": "limits-formula" }, () => {
    const v = current.values.val;
    const rule = currentLimits(v.motorStall ?? 0, v.motorPeak ?? 0, v.driveMax ?? 0, v.driveRated ?? 0);
    const problems = v.ratedCurrent !== undefined && v.maxCurrent !== undefined ? limitProblems(v.ratedCurrent, v.maxCurrent, v.driveMax ?? 0) : [];
    return [
      h("pre", { class: "mono", style: { margin: "0", whiteSpace: "pre-wrap" } },
        "rated current 0x6075 = min(motor stall current, drive rated current)\n",
        "max current 0x6073   = min(motor peak current, drive max current) / rated current   [% of rated]\n",
        "ranges (manual §1.8.8): max current 20–100 %, rated current (the I²t threshold) 20–50 % of the drive current rating"),
      h("table", { class: "data kv" }, h("tbody", null,
        h("tr", null, h("td", null, "Motor stall / peak current"), h("td", { class: "num" }, `${shown(current, "motorStall")} / ${shown(current, "motorPeak")}`)),
        h("tr", null, h("td", null, "On the drive: rated / max"), h("td", { class: "num", "data-testid": "limits-now" }, `${shown(current, "ratedCurrent")} / ${shown(current, "maxCurrent")}`)),
        h("tr", null, h("td", null, "The rule gives"), h("td", { class: "num", "data-testid": "limits-rule" }, rule ? `${sig(rule.rated, "A")} / ${sig(rule.maxPercent, "%")}` : "— (motor data missing)")))),
      problems.length ? h("div", { class: "message warn", "data-testid": "limits-problems" }, `Out of the manual's range: ${problems.join("; ")}.`) : null,
    ];
  });
}

/** I²t: the mode (Limiting / Fusing, 0x3404,1) with Apply, and the times to warning and limitation (manual §6.3). */
export function i2tPanel(model: ProceduresModel, current: CurrentValues): HTMLElement {
  const message = state<Message | null>(null);
  const variable = current.variables.i2tMode;
  const chosen = state<string>("1");
  const apply = async () => {
    try {
      const answer = await driveApi.writeKey(model.where.bus, model.where.node, current.keys.i2tMode!, Number(chosen.rawVal));
      message.val = { text: `I²t mode is now ${answer.text || answer.raw}.`, tone: "ok", testid: "i2t-written" };
      await current.reload();
    } catch (error) {
      message.val = { text: `I²t mode: ${errorText(error)}`, tone: "error", testid: "i2t-failed" };
    }
  };
  const mode = () => current.values.val.i2tMode;
  return h("section", { class: "panel", "data-testid": "i2t-panel" }, h("h2", null, "I²t protection"),
    h("div", { class: "panel-body grid", style: { gap: "8px" } },
      variable ? h("div", { class: "toolbar" }, h("span", null, "Mode on the drive: ", h("strong", { "data-testid": "i2t-mode" }, () => {
        const raw = mode();
        return raw === undefined ? "—" : `${variable.enum[String(raw)] ?? raw} (${raw})`;
      })),
      h("select", { "data-testid": "i2t-select", value: chosen, onchange: (event: Event) => (chosen.val = (event.target as HTMLSelectElement).value) },
        h("option", { value: "1" }, "Fusing (recommended while commissioning)"), h("option", { value: "0" }, "Limiting")),
      h("button", { "data-testid": "i2t-apply", onclick: () => void apply() }, "Apply")) : h("div", { class: "muted" }, "This drive's dictionary has no I²t mode."),
      h("div", { class: "muted" }, "Fusing: at 85 % of the rated current (RMS) a warning; not back below 85 % within 1 s → I²t error (38), the drive is disabled. ",
        "Limiting: the same warning, the current limited to the rated current, no error."),
      h("div", { "data-testid": "i2t-times" }, () => i2tTimesView(current.values.val.maxCurrent)),
      messageView(message)));
}

function i2tTimesView(maxPercent: number | undefined): HTMLElement {
  const times = maxPercent === undefined ? null : i2tTimes(maxPercent);
  const s = (value: number) => `${sig(value)} s`;
  return h("div", null,
    h("pre", { class: "mono", style: { margin: "0", whiteSpace: "pre-wrap" } },
      "r = I_rated / I_max\n",
      "time to the warning    T_dyn = 3.3·r² s (shaft locked)   10·r² s (running, current frequency > 2 Hz)\n",
      "time to the limitation T_max = 4·r² s   (shaft locked)   12·r² s (running)      (accurate for I_max/I_rated > 1.5)"),
    times ? h("div", null, `With the drive's max current ${sig(maxPercent, "%")} of rated: r = ${sig(times.r)} → warning after ${s(times.lockedWarning)} locked / ${s(times.runningWarning)} running, `,
      `limitation after ${s(times.lockedLimit)} locked / ${s(times.runningLimit)} running.`) : null);
}
