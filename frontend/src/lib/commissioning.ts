/**
 * The commissioning order of the XtrapulsPac manual (§1.8: device config → motor → sensors → current → I²t and
 * thermal → phasing → scaling → tuning → quick test → I/O → braking → save) and, per step, the objects whose
 * project values show that the step was done. Other devices use the steps whose objects their dictionary has.
 */

import { entryKey, type Dictionary } from "./od";

export interface StepObject {
  index: number;
  /** null: every writable sub of the object */
  subindex: number | null;
}

export interface Step {
  key: string;
  title: string;
  /** What the manual says to do, in one line. */
  summary: string;
  objects: StepObject[];
  /** Page that does the step, when it is not the parameter editor. */
  page?: "motors" | "dashboard" | "backup" | "template" | "current-loop" | "phasing" | "tuning";
  /** Done by an action, not by values: the user ticks it (quick test, save). */
  manual?: boolean;
}

const o = (index: number, subindex: number | null = 0): StepObject => ({ index, subindex });

export const STEPS: Step[] = [
  { key: "config", title: "Drive configuration", summary: "Choose the application template (Device Config) or Expert mode.", objects: [], page: "template" },
  { key: "motor", title: "Motor", summary: "Pick the motor from the catalog or enter rated/peak current, speed, pole pairs, inductance.", objects: [o(0x6410, null)], page: "motors" },
  { key: "sensors", title: "Sensors", summary: "Motor and position-loop sensors, resolver/encoder setup, direction, zero mark.", objects: [o(0x3070), o(0x306a), o(0x3101, 1), o(0x3121, 1), o(0x3181, 1)] },
  { key: "current", title: "Current", summary: "Maximum and rated current, inductance, current loop gains ('calc').", objects: [o(0x6073), o(0x6075), o(0x340f), o(0x60f6, null)], page: "current-loop" },
  { key: "thermal", title: "I²t and thermal", summary: "I²t mode (fusing while commissioning), motor temperature sensor and thresholds.", objects: [o(0x3404, 1), o(0x3324, null)], page: "current-loop" },
  { key: "phasing", title: "Phasing", summary: "Auto-phasing ('apha') or motor phasing: pole pairs, phase order, offset.", objects: [o(0x3410, null), o(0x313e)], page: "phasing" },
  { key: "scaling", title: "Scaling", summary: "Position unit, display factor, load displacement per motor revolution.", objects: [o(0x308a), o(0x3089), o(0x6093, 2)] },
  { key: "tuning", title: "Tuning", summary: "Auto-tuning, speed and position gains, filters, following-error thresholds.", objects: [o(0x60f9, null), o(0x60fb, null), o(0x30fa), o(0x306d), o(0x6065), o(0x3065)], page: "tuning" },
  { key: "quicktest", title: "Quick test", summary: "Enable the drive, move slowly in profile velocity and position mode, check stability.", objects: [o(0x607f), o(0x6083), o(0x6084)], page: "dashboard", manual: true },
  { key: "io", title: "Inputs and outputs", summary: "Assign logic input/output functions and polarities (limit switches fail-safe).", objects: [o(0x3050, null), o(0x3051), o(0x3054, null), o(0x3055)] },
  { key: "braking", title: "Braking", summary: "Braking resistor (stand-alone mains supply) and undervoltage warning threshold.", objects: [o(0x33b0, null), o(0x3079)] },
  { key: "save", title: "Save", summary: "Store the parameters to the drive's flash and back them up into the project.", objects: [], page: "backup", manual: true },
];

/** The (index, sub) keys a step checks in this dictionary: writable, saved entries of its objects. */
export function stepKeys(step: Step, dictionary: Dictionary): string[] {
  const keys: string[] = [];
  for (const wanted of step.objects) {
    const object = dictionary.objects.find((candidate) => candidate.index === wanted.index);
    if (!object) continue;
    for (const variable of object.subs) {
      if (wanted.subindex !== null && variable.subindex !== wanted.subindex) continue;
      if (wanted.subindex === null && (variable.save_type === "NONE" || !/w/i.test(variable.access))) continue;
      keys.push(entryKey(object.index, variable.subindex));
    }
  }
  return keys;
}

export type StepState = "done" | "partial" | "open" | "not-applicable";

export interface StepStatus {
  state: StepState;
  set: number;
  total: number;
}

/**
 * A value step is done when the project sets every entry it checks, partial when it sets some. Manual steps are
 * done when ticked; steps without objects in this dictionary are not applicable unless they are manual.
 */
export function stepStatus(step: Step, keys: string[], explicit: ReadonlySet<string>, ticked: boolean, extraDone = false): StepStatus {
  const set = keys.filter((key) => explicit.has(key)).length;
  if (step.manual || step.page === "template") {
    return { state: ticked || extraDone ? "done" : set > 0 ? "partial" : "open", set, total: keys.length };
  }
  if (keys.length === 0) return { state: extraDone ? "done" : "not-applicable", set, total: 0 };
  if (extraDone || set === keys.length) return { state: "done", set, total: keys.length };
  return { state: set > 0 ? "partial" : "open", set, total: keys.length };
}
