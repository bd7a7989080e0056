/** Bit fields of status/control words and masks (the dictionary's `bits`: single bits and bit ranges). */

export interface BitField {
  first: number;
  last: number;
  name: string;
}

export interface DecodedField extends BitField {
  value: number;
}

/** Value of bits first..last of `word` (up to 53-bit words; no 32-bit sign surprises of the `>>` operator). */
export function extractBits(word: number, first: number, last: number): number {
  const width = last - first + 1;
  return Math.floor(word / 2 ** first) % 2 ** width;
}

/** Return `word` with bits first..last replaced by `value` (which must fit the field). */
export function insertBits(word: number, first: number, last: number, value: number): number {
  const width = last - first + 1;
  if (!Number.isInteger(value) || value < 0 || value >= 2 ** width) {
    throw new RangeError(`value ${value} does not fit bits ${first}..${last}`);
  }
  const old = extractBits(word, first, last);
  return word + (value - old) * 2 ** first;
}

/** Every field of `bits` with its value in `word`, in bit order. */
export function decodeBits(word: number, bits: readonly BitField[]): DecodedField[] {
  return [...bits]
    .sort((a, b) => a.first - b.first)
    .map((field) => ({ ...field, value: extractBits(word, field.first, field.last) }));
}

/** The label a field gets in the UI: "8-9" for a range, "3" for a single bit. */
export function fieldLabel(field: BitField): string {
  return field.first === field.last ? String(field.first) : `${field.first}-${field.last}`;
}
