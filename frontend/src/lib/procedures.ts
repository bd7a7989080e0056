/**
 * What the procedure pages say and decide, without DOM: the manual's safety checklists, when Start is allowed (and
 * why not), the meaning of each gain a procedure writes, the phase order's text, and the I²t and current-limit
 * formulas of the XtrapulsPac manual (§1.8.8–1.8.11, §6.3, §6.8).
 */

import type { ProcedureInfo } from "../client/procedures";

/** Manual §1.8.13 and §4.2 (auto-phasing), L6594–6600 (motor phasing), §1.8.16 (auto-tuning). */
export const CHECKLISTS: Record<string, string[]> = {
  auto_phasing: [
    "The motor is free or uncoupled from the load",
    "The shaft can turn one revolution without danger",
    "The limit switches are not active",
    "The brake is released (the procedure does not control it)",
    "Max and rated current suit the motor (current limit)",
  ],
  motor_phasing: [
    "The motor is at standstill; no vertical axis and no driving load",
    "The shaft can turn one revolution without danger (motor phasing applies torque)",
    "The limit switches are not active",
    "The brake is released (the procedure does not control it)",
    "Max and rated current suit the motor (current limit)",
  ],
  auto_tuning: [
    "The motor is free or uncoupled, or at standstill when tuning an enabled (vertical) axis",
    "The shaft can turn one revolution without danger",
    "The limit switches are not active",
    "The brake is released: auto-tuning does not control the brake",
    "Max and rated current suit the motor (current limit)",
  ],
};

/**
 * Why Start is not allowed now, or null when it is: a run in progress, the drive not offering the procedure, a
 * precondition the drive does not meet (with the manual's reason) unless the options provide it (`provided`: an
 * inductance typed for 'calc' is written first), an unticked checklist item, or a moving procedure on an axis this
 * page has not armed.
 */
export function startBlock(info: ProcedureInfo | undefined, armed: boolean, unticked: string[], running: boolean,
  provided: readonly string[] = []): string | null {
  if (running) return "The procedure is running.";
  if (!info) return "The drive does not offer this procedure.";
  const unmet = info.preconditions.filter((condition) => !condition.ok && !provided.includes(condition.name));
  if (unmet.length > 0) return unmet.map((condition) => `${condition.label}: ${condition.reason ?? "not met"}`).join("; ");
  if (unticked.length > 0) return `Tick the safety checklist first (${unticked.length} left: ${unticked[0]}).`;
  if (info.moves && !armed) return "Arm the axis first: this procedure turns the motor.";
  return null;
}

/** Gains and limits by semantic name: the manual's short name and what it does (§1.8.17, §4.4, §4.11). */
export const GAIN_MEANINGS: Record<string, [string, string]> = {
  kp_speed: ["KPv", "speed loop proportional gain on the speed error"],
  ki_speed: ["KIv", "speed loop integral gain on the speed error"],
  ki_speed_filter: ["KIvf", "integrator low-frequency limit (less heating under dry friction)"],
  kc_speed: ["KCv", "damping: proportional on the speed feedback only; less overshoot on steps"],
  kd_speed: ["KDv", "derivative gain"],
  kd_speed_filter: ["KDvf", "derivative high-frequency limit"],
  kj_speed: ["KJv", "gain scaling factor: multiplies the speed regulator gains"],
  kp_position: ["KPp", "position loop proportional gain (0 when tuned in profile velocity)"],
  kf_position: ["KFp", "speed feed-forward (65535 = full: minimum following error)"],
  ka_position: ["KAv", "acceleration feed-forward (inertia compensation)"],
  kb_position: ["KBv", "speed feed-forward 2: damping and viscous-friction compensation"],
  ka_speed: ["KAv", "acceleration feed-forward (inertia compensation)"],
  kb_speed: ["KBv", "speed feed-forward 2: damping and viscous-friction compensation"],
  speed_filter: ["Speed filter", "speed measurement filter time constant (0x30FA)"],
  speed_measurement_filter: ["Speed filter", "speed measurement filter time constant (0x30FA)"],
  current_filter_1: ["Current filter 1", "current command filter, first stage (Hz, 0 = off; set by the anti-resonance filter)"],
  current_filter_2: ["Current filter 2", "current command filter, second stage (Hz, 0 = off)"],
  current_filter_3: ["Current filter 3", "current command filter, third stage (Hz, 0 = off)"],
  current_regulator_type: ["Regulator", "current loop bandwidth: 0 high (900 Hz), 1 low (400 Hz, less whistling)"],
  kp_current_q: ["Kp q", "q-axis (torque) current loop proportional gain"],
  ki_current_q: ["Ki q", "q-axis (torque) current loop integral gain"],
  kp_current_d: ["Kp d", "d-axis (flux) current loop proportional gain"],
  ki_current_d: ["Ki d", "d-axis (flux) current loop integral gain"],
  max_current: ["Max current", "0x6073, ‰ of the rated current"],
  rated_current: ["Rated current", "0x6075, mA: the I²t threshold"],
};

export function gainMeaning(name: string): [string, string] {
  return GAIN_MEANINGS[name] ?? [name, ""];
}

/** The rows of a before → after table: every name either side has, in the order of the "after" values. */
export function changeRows(before: Record<string, number>, after: Record<string, number>): { name: string; before?: number; after?: number; changed: boolean }[] {
  const names = [...Object.keys(after), ...Object.keys(before).filter((name) => !Object.hasOwn(after, name))];
  const of = (values: Record<string, number>, name: string) => (Object.hasOwn(values, name) ? values[name] : undefined);
  return names.map((name) => ({ name, before: of(before, name), after: of(after, name), changed: of(before, name) !== of(after, name) }));
}

/** 0x3410,2: 0x5555 = 240° (U-V-W), 0xAAAA = 120° (U-W-V); the CD1-k's 0/1. */
export function phaseOrderText(value: number | undefined): string {
  if (value === undefined) return "—";
  if (value === 0x5555) return "0x5555 (240°, U-V-W)";
  if (value === 0xaaaa) return "0xAAAA (120°, U-W-V)";
  return String(value);
}

/** The sensor offset in 1/65536 of a turn, also as electrical degrees with the pole pairs when they are known. */
export function offsetText(offset: number | undefined, polePairs?: number): string {
  if (offset === undefined) return "—";
  const degrees = polePairs ? ` (${((offset / 65536) * 360 * polePairs % 360).toFixed(1)}° el.)` : "";
  return `${offset}${degrees}`;
}

/** I²t timings of manual §6.3 for r = I_rated / I_max (max current in % of the rated, as 0x6073 shows it): seconds. */
export function i2tTimes(maxPercent: number): { r: number; lockedWarning: number; lockedLimit: number; runningWarning: number; runningLimit: number } | null {
  if (!(maxPercent > 0)) return null;
  const r = 100 / maxPercent;
  const square = r * r;
  return { r, lockedWarning: 3.3 * square, lockedLimit: 4 * square, runningWarning: 10 * square, runningLimit: 12 * square };
}

/** The current-limit calculation (0x3412, manual §6.8): rated = min(stall, drive rated) A, max = min(peak, drive max) in % of it. */
export function currentLimits(stall: number, peak: number, driveMax: number, driveRated: number): { rated: number; maxPercent: number } | null {
  const positive = (values: number[]) => values.filter((value) => value > 0);
  const rated = Math.min(...positive([stall, driveRated]));
  const top = Math.min(...positive([peak, driveMax]));
  if (!Number.isFinite(rated) || !Number.isFinite(top)) return null;
  return { rated, maxPercent: Math.min(3276.7, Math.round((1000 * top) / rated) / 10) };
}

/** The GUI's ranges (manual §1.8.8): max current 20–100 %, rated current 20–50 % of the drive current rating. */
export function limitProblems(rated: number, maxPercent: number, driveMax: number): string[] {
  if (!(driveMax > 0)) return [];
  const maxShare = (rated * maxPercent) / 100 / driveMax;
  const ratedShare = rated / driveMax;
  const problems: string[] = [];
  if (maxShare < 0.2 || maxShare > 1.0001) problems.push(`max current is ${(maxShare * 100).toFixed(0)} % of the drive rating (20–100 %)`);
  if (ratedShare < 0.2 || ratedShare > 0.5001) problems.push(`rated current is ${(ratedShare * 100).toFixed(0)} % of the drive rating (20–50 %)`);
  return problems;
}

/** Quantities the current-loop page shows, per device: (index, sub) in that device's dictionary. */
export type CurrentQuantity = "inductance" | "driveMax" | "driveRated" | "motorStall" | "motorPeak" | "maxCurrent" | "ratedCurrent" | "i2tMode";

export const CURRENT_ENTRIES: Record<string, Partial<Record<CurrentQuantity, [number, number]>>> = {
  xtrapulspac: {
    inductance: [0x340f, 0], driveMax: [0x6510, 1], driveRated: [0x6510, 2], motorStall: [0x6410, 9], motorPeak: [0x6410, 10],
    maxCurrent: [0x6073, 0], ratedCurrent: [0x6075, 0], i2tMode: [0x3404, 1],
  },
};

/** A number for a result table: 4 significant digits, exponent for very small or large values. */
export function sig(value: number | null | undefined, unit = ""): string {
  if (value === null || value === undefined || !Number.isFinite(value)) return "—";
  const text = value !== 0 && (Math.abs(value) < 1e-3 || Math.abs(value) >= 1e6) ? Number(value.toPrecision(4)).toExponential() : String(Number(value.toPrecision(4)));
  return unit ? `${text} ${unit}` : text;
}

/** The drive warns that motor phasing is needed (XtrapulsPac warning 31, bit 30 "Motor phasing init not OK"). */
export function needsMotorPhasing(warnings: { code: number; name: string }[]): boolean {
  return warnings.some((warning) => /motor phasing/i.test(warning.name));
}
