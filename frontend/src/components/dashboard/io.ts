/**
 * Digital I/O (0x60FD inputs, 0x60FE,1 outputs) as LEDs named by their bit fields, or by the names the I/O
 * configuration gives them (the input and its function: `lib/io-names.ts`) once those are known.
 */

import { type BitField, extractBits, fieldLabel } from "../../lib/bits";
import { h } from "../../lib/dom";
import type { IoNames } from "../../lib/io-names";
import type { Entry } from "../../lib/od";

export interface DigitalIoProps {
  inputs: Entry | null;
  outputs: Entry | null;
  /** The live word of an entry (null until it arrived); read inside bindings. */
  word(entry: Entry): number | null;
  address(entry: Entry): string;
  /** The I/O configuration's names (null until read, or when the device has none); read inside bindings. */
  names?(): IoNames | null;
}

export function digitalIo(props: DigitalIoProps): HTMLElement {
  const groups: HTMLElement[] = [];
  if (props.inputs) groups.push(ioGroup("Inputs", props.inputs, props));
  if (props.outputs) groups.push(ioGroup("Outputs", props.outputs, props));
  return h("section", { class: "panel" }, h("h2", null, "Digital I/O"),
    h("div", { class: "panel-body" }, groups.length ? groups : h("div", { class: "muted" }, "This dictionary has no digital I/O objects.")));
}

/** CiA 402 gives bits 0–15 of the I/O words their meaning for the drive (limit switches, home, interlock; the
 * brake) and leaves bits 16–31 to the device's own terminals. */
const DEVICE_BITS_FROM = 16;

function ioGroup(title: string, entry: Entry, props: DigitalIoProps): HTMLElement {
  const word = () => props.word(entry);
  const key = title.toLowerCase();
  const terminals = entry.variable.bits.filter((field) => field.first >= DEVICE_BITS_FROM);
  const functions = entry.variable.bits.filter((field) => field.first < DEVICE_BITS_FROM);
  const split = terminals.length > 0 && functions.length > 0;
  return h("div", { style: { marginBottom: "8px" } },
    h("div", { class: "muted", style: { marginBottom: "4px" } }, `${title} · ${props.address(entry)}`, () => {
      const value = word();
      return value === null ? "" : ` = 0x${value.toString(16).toUpperCase().padStart(8, "0")}`;
    }),
    h("div", { class: "io-row", "data-testid": `io-${key}` }, (split ? terminals : entry.variable.bits).map((field) => led(title, field, word, props))),
    split ? h("div", { class: "io-row", "data-testid": `io-${key}-functions`, title: "What the drive makes of its inputs (CiA 402 bits 0–15)" },
      h("span", { class: "muted" }, "drive sees:"), functions.map((field) => led(title, field, word, props))) : null);
}

function led(title: string, field: BitField, word: () => number | null, props: DigitalIoProps): HTMLElement {
  const named = () => (title === "Inputs" ? props.names?.()?.inputs : props.names?.()?.outputs)?.get(field.first) ?? null;
  return h("span", {
    class: () => {
      const value = word();
      return `led ${value !== null && extractBits(value, field.first, field.last) !== 0 ? "on" : ""}`;
    },
    title: () => `bit ${fieldLabel(field)}: ${named() ?? field.name}`,
  }, () => {
    const label = named();
    return label ? configuredName(label) : shortName(field.name);
  });
}

/** An LED label from the I/O configuration's "IN3: Positive limit switch" → "IN3 LIM+", "INPUT0 / LS+" → "INPUT0". */
export function configuredName(label: string): string {
  const [line, function_] = label.split(": ");
  const name = line.split(" ")[0];
  const short = function_ ? shortName(function_) : "";
  return short && short.toLowerCase() !== name.toLowerCase() ? `${name} ${short}` : name;
}

/** A short LED label from a bit name: "IN1", "Negative limit switch" → "LIM−", "Home switch" → "Home". */
export function shortName(name: string): string {
  const match = /\b(IN|OUT)\s*(\d+)\b/i.exec(name);
  if (match) return `${match[1].toUpperCase()}${match[2]}`;
  if (/negative limit/i.test(name)) return "LIM−";
  if (/positive limit/i.test(name)) return "LIM+";
  const words = name.split(/[\s/(),]+/).filter(Boolean);
  return words.length ? words[0].slice(0, 8) : name;
}
