/**
 * Showing and entering the value of one dictionary entry. Values travel as raw object values (what the drive
 * stores); the user reads and types physical values: physical = raw * scale + offset, in the entry's unit.
 */

import { formatHex, formatNumber, fromPhysical, parseNumber, roundNoise, toPhysical } from "./numbers";
import { hexWidth, rawRange, valueKind, type OdVariable, type Scalar } from "./od";

/** Significant digits of a REAL readout: a REAL32 holds about 7, the digits after them are the float's noise. */
export const FLOAT_DIGITS = 7;
/** Significant digits of a live readout (a measurement that changes at every sample): the last ones only flicker. */
export const LIVE_DIGITS = 5;

/**
 * The value as a table cell or readout shows it: enum text, hex word, pointer, physical number or text. A scaled
 * integer shows its resolution (the decimals of one step of the scale), a REAL `FLOAT_DIGITS` significant digits;
 * `digits` (a live readout: `LIVE_DIGITS`) caps the significant digits further. Only what is shown is rounded: an
 * edit field starts from `editText`, which keeps every digit.
 */
export function formatValue(variable: OdVariable, raw: Scalar | undefined, digits?: number): string {
  if (raw === null || raw === undefined) return "";
  if (typeof raw === "string") return raw;
  const kind = valueKind(variable.data_type);
  if (kind === "integer") {
    const text = variable.enum[String(raw)];
    if (text !== undefined) return `${text} (${raw})`;
    if (variable.is_pointer) return formatHex(raw, 8);
    if (variable.bits.length > 0) return formatHex(raw, hexWidth(variable.data_type));
  }
  return formatReadout(variable, raw, kind === "integer", digits);
}

function formatReadout(variable: OdVariable, raw: number, integer: boolean, digits?: number): string {
  const physical = toPhysical(raw, variable.scale, variable.offset);
  if (!integer) return formatNumber(physical, Math.min(digits ?? FLOAT_DIGITS, FLOAT_DIGITS));
  const stepped = Number(physical.toFixed(resolutionDecimals(variable)));
  return formatNumber(stepped, digits ?? 15);
}

/**
 * Decimals that tell two neighbouring raw values of an integer entry apart: those of one scale step (0.1 → 1,
 * 0.0061 → 3) and of the offset (2.5 → 1).
 */
export function resolutionDecimals(variable: OdVariable): number {
  const step = Math.abs(variable.scale || 1);
  const ofStep = Math.max(0, Math.ceil(-Math.log10(step) - 1e-9));
  const offset = roundNoise(variable.offset || 0);
  const ofOffset = Number.isInteger(offset) ? 0 : (String(offset).split(".")[1]?.length ?? 0);
  return Math.min(Math.max(ofStep, ofOffset), 12);
}

/** Plain text for an input field: the physical number, hex for words and pointers, the raw text otherwise. */
export function editText(variable: OdVariable, raw: Scalar | undefined): string {
  if (raw === null || raw === undefined) return "";
  if (typeof raw === "string") return raw;
  if (variable.is_pointer || variable.bits.length > 0) return formatHex(raw, hexWidth(variable.data_type));
  return formatNumber(toPhysical(raw, variable.scale, variable.offset));
}

export type ParsedValue = { ok: true; raw: number | string } | { ok: false; error: string };

/**
 * Turn what the user typed into the raw value to write, checked against the entry's range. Words (bit fields,
 * pointers) are typed raw (hex), everything else physical. The server checks again; this gives the message early.
 */
export function parseValue(variable: OdVariable, text: string): ParsedValue {
  const kind = valueKind(variable.data_type);
  if (kind === "string" || kind === "bytes") return { ok: true, raw: text };
  const parsed = parseNumber(text);
  if (!parsed.ok) return parsed;
  const rawInput = variable.is_pointer || variable.bits.length > 0;
  const exact = rawInput ? parsed.value : fromPhysical(parsed.value, variable.scale, variable.offset, false);
  const raw = kind === "integer" ? Math.round(exact) : exact;
  if (Math.abs(raw - exact) > 1e-6 * Math.max(1, Math.abs(exact))) {
    const step = formatNumber(variable.scale || 1);
    return { ok: false, error: step === "1" ? `${text} is not a whole number` : `${text} is not a multiple of ${step}` };
  }
  const range = rawRange(variable);
  if (range && (raw < range[0] || raw > range[1])) {
    return { ok: false, error: `${text} is outside ${formatRange(variable)}` };
  }
  return { ok: true, raw };
}

/** The allowed range in the units the user types: `0 … 65535`, `-10 … 10 A`. */
export function formatRange(variable: OdVariable): string {
  const range = rawRange(variable);
  if (!range) return "";
  if (variable.is_pointer || variable.bits.length > 0) {
    const width = hexWidth(variable.data_type);
    return `${formatHex(range[0], width)} … ${formatHex(range[1], width)}`;
  }
  const low = toPhysical(range[0], variable.scale, variable.offset);
  const high = toPhysical(range[1], variable.scale, variable.offset);
  const [min, max] = low <= high ? [low, high] : [high, low];
  return `${formatNumber(min)} … ${formatNumber(max)}${variable.unit ? " " + variable.unit : ""}`;
}

/** Equal as drive values? Numbers compare exactly, texts as written. */
export function sameValue(a: Scalar | undefined, b: Scalar | undefined): boolean {
  if (a === undefined || b === undefined || a === null || b === null) return a === b;
  return typeof a === "number" && typeof b === "number" ? a === b : String(a) === String(b);
}

/**
 * Why the project would refuse to store this drive value, or null: numbers outside the dictionary's range (a drive
 * may hold one) and texts the object files cannot hold (empty, or with leading/trailing spaces). Checking first
 * spares a refused batch and its retry.
 */
export function unstorableReason(variable: OdVariable, raw: Scalar): string | null {
  if (raw === null) return "no value";
  if (typeof raw === "string") {
    if (valueKind(variable.data_type) !== "string") return null;
    return raw === "" || raw.trim() !== raw ? `text ${JSON.stringify(raw)} is empty or has leading/trailing spaces` : null;
  }
  const range = rawRange(variable);
  return range && (raw < range[0] || raw > range[1]) ? `${raw} is outside ${range[0]}..${range[1]}` : null;
}
