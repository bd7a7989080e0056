/** Dictionary entries for the component tests. */

import type { Entry, OdObject, OdVariable } from "../lib/od";

export function variable(overrides: Partial<OdVariable> = {}): OdVariable {
  return {
    subindex: 0, name: "Value", data_type: "UNSIGNED16", access: "rw", pdo_mappable: false, low: null, high: null,
    default: 0, unit: "", scale: 1, offset: 0, save_type: "DRIVEPAR", group: "General", description: "", enum: {},
    bits: [], is_pointer: false, reference: "", write_level: null, ...overrides,
  } as OdVariable;
}

export function entry(index: number, overrides: Partial<OdVariable> = {}, object: Partial<OdObject> = {}): Entry {
  const sub = variable(overrides);
  const owner = { index, name: sub.name, kind: "VAR", group: sub.group, subs: [sub], ...object } as OdObject;
  return { key: `${index}.${sub.subindex}`, object: owner, variable: sub };
}

/** Type into a text field as the user does (value, then the input event). */
export function type(input: HTMLInputElement, text: string): void {
  input.value = text;
  input.dispatchEvent(new Event("input"));
}

export function press(element: HTMLElement, key: string): void {
  element.dispatchEvent(new KeyboardEvent("keydown", { key, bubbles: true }));
}

export function choose(select: HTMLSelectElement, value: string): void {
  select.value = value;
  select.dispatchEvent(new Event("change"));
}
