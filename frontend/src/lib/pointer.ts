/**
 * Dataflow pointers of the XtrapulsPac: a U32 `index << 16 | sub << 8 | bit-or-size` that links one object to
 * another (0x3050, 0x30FF, the oscilloscope channels; manual L1486-1502).
 */

import { formatHex } from "./numbers";

export interface PointerTarget {
  index: number;
  subindex: number;
  bit: number;
}

export function encodePointer(target: PointerTarget): number {
  const { index, subindex, bit } = target;
  if (!inRange(index, 0xffff) || !inRange(subindex, 0xff) || !inRange(bit, 0xff)) {
    throw new RangeError(`pointer fields out of range: index ${index}, sub ${subindex}, bit ${bit}`);
  }
  // Multiplication, not <<: index << 16 turns negative for index >= 0x8000.
  return index * 0x10000 + subindex * 0x100 + bit;
}

export function decodePointer(value: number): PointerTarget {
  if (!inRange(value, 0xffffffff)) throw new RangeError(`pointer value ${value} is not a U32`);
  return { index: Math.floor(value / 0x10000), subindex: Math.floor(value / 0x100) % 0x100, bit: value % 0x100 };
}

/** `0x60FD.0 bit 16` style text, used next to the raw hex value. */
export function formatPointer(value: number): string {
  if (value === 0) return "not linked";
  const { index, subindex, bit } = decodePointer(value);
  return `${formatHex(index)}.${subindex} / ${bit}`;
}

function inRange(value: number, max: number): boolean {
  return Number.isInteger(value) && value >= 0 && value <= max;
}
