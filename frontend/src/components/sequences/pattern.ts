/**
 * A bit-pattern editor (Output, StartCond, EndCond): 8 cells, bit 7 on the left as in the file; a click steps a cell
 * through . (unchanged / don't care), 1 (set / must be 1) and 0 (reset / must be 0). Each cell names its bit as the
 * manual does: the conditions test the conditional input 0x3601,3, whose bit n is "logic input n+1" (bit 7 is input
 * 8 in the conditional-jump example); the outputs are the programmable outputs 0x3602,1 (bit n: output n+1).
 * Where the drive's I/O configuration routes an input to a condition bit, or shows a sequence output on an output
 * (docs/io.md), the cell takes that input's or output's name.
 */

import { h } from "../../lib/dom";
import type { IoNames } from "../../lib/io-names";
import { EMPTY_PATTERN, PATTERN_WIDTH, stepBit } from "./text";

export function bitName(keyword: string, bit: number, names: IoNames | null = null): string {
  if (keyword === "Output") return names?.sequenceOutputs.get(bit) ?? `OUT${bit + 1}`;
  return names?.conditions.get(bit) ?? `IN${bit + 1}`;
}

export function patternEditor(keyword: string, pattern: string, set: (next: string) => void, names: IoNames | null = null): HTMLElement {
  const current = pattern || EMPTY_PATTERN;
  const bits = Array.from({ length: PATTERN_WIDTH }, (_, index) => PATTERN_WIDTH - 1 - index);
  return h("span", { "data-testid": `pattern-${keyword}`, style: { display: "inline-flex", gap: "2px" } },
    bits.map((bit) => h("button", {
      type: "button",
      "data-testid": `pattern-${keyword}-bit${bit}`,
      title: `bit ${bit}: ${bitName(keyword, bit, names)}`,
      style: { width: "34px", padding: "1px", fontFamily: "monospace", lineHeight: "1.1" },
      onclick: () => set(stepBit(current, bit)),
    }, current[PATTERN_WIDTH - 1 - bit] ?? ".", h("br"), h("small", null, bitName(keyword, bit, names)))));
}
