/**
 * Locale-independent number parsing and formatting.
 *
 * The drives' manual allows only "." as decimal separator and no thousands separator (L333-335), and the tool must
 * behave the same in every browser locale, so nothing here uses Intl or toLocaleString.
 */

export type Parsed = { ok: true; value: number } | { ok: false; error: string };

const DECIMAL = /^[+-]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?$/i;
const HEX = /^[+-]?0x[0-9a-f]+$/i;
const BINARY = /^[+-]?0b[01]+$/i;

/** Parse user input: decimal (`-12.5`, `1e-3`), hexadecimal (`0x60F9`) or binary (`0b1010`). */
export function parseNumber(input: string): Parsed {
  const text = input.trim().replace(/_/g, "");
  if (text === "") return { ok: false, error: "enter a number" };
  if (HEX.test(text)) return { ok: true, value: signed(text, (digits) => parseInt(digits.slice(2), 16)) };
  if (BINARY.test(text)) return { ok: true, value: signed(text, (digits) => parseInt(digits.slice(2), 2)) };
  if (DECIMAL.test(text)) return { ok: true, value: Number(text) };
  if (/^[+-]?\d+,\d+$/.test(text)) return { ok: false, error: `"${input.trim()}": use "." as decimal separator` };
  if (/\d[ ,']\d{3}/.test(text)) return { ok: false, error: `"${input.trim()}": no thousands separators` };
  return { ok: false, error: `"${input.trim()}" is not a number` };
}

function signed(text: string, parse: (digits: string) => number): number {
  const negative = text.startsWith("-");
  const digits = text.replace(/^[+-]/, "");
  return negative ? -parse(digits) : parse(digits);
}

/**
 * Format a number with "." as decimal separator, at most `digits` significant digits, without exponent for the
 * range an engineer reads at a glance (1e-6 .. 1e15), and without trailing zeros.
 */
export function formatNumber(value: number, digits = 10): string {
  if (!Number.isFinite(value)) return String(value);
  if (Number.isInteger(value) && Math.abs(value) < 1e15) return String(value);
  const magnitude = Math.abs(value);
  if (magnitude !== 0 && (magnitude < 1e-6 || magnitude >= 1e15)) return value.toExponential(digits - 1).replace(/\.?0+e/, "e");
  const decimals = Math.max(0, digits - 1 - Math.floor(Math.log10(magnitude || 1)));
  const fixed = value.toFixed(Math.min(decimals, 12));
  return fixed.includes(".") ? fixed.replace(/\.?0+$/, "") : fixed;
}

/** `0x60F9`, zero-padded to `width` hex digits. */
export function formatHex(value: number, width = 4): string {
  const sign = value < 0 ? "-" : "";
  return sign + "0x" + Math.abs(value).toString(16).toUpperCase().padStart(width, "0");
}

/** Physical value of a raw value: physical = raw * scale + offset (docs/eds.md). */
export function toPhysical(raw: number, scale = 1, offset = 0): number {
  return roundNoise(raw * scale + offset);
}

/** Raw value of a physical value; integer data types round to the nearest step. */
export function fromPhysical(physical: number, scale = 1, offset = 0, integer = true): number {
  const raw = (physical - offset) / (scale || 1);
  return integer ? Math.round(raw) : raw;
}

/** Remove binary floating-point noise such as 0.30000000000000004 before showing a value. */
export function roundNoise(value: number): number {
  return Number.isInteger(value) ? value : Number(value.toPrecision(12));
}
