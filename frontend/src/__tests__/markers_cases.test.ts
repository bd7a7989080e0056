/**
 * The shared table of marker cases (tests/services/frequency/markers_cases.json, written and checked by the
 * backend's test_markers_coherence.py): synthetic responses with incoherent points whose true markers are known.
 * The frontend's markers must find what the backend's found (a closed-loop measurement: its bandwidth; the margins
 * are the model's open loop's here, taken on the "open" cases).
 */

import { describe, expect, it } from "vitest";
import cases from "../../../tests/services/frequency/markers_cases.json";
import { responseOf } from "../lib/whatif/loop";
import { bandwidth, margins, resonances } from "../lib/whatif/markers";

type Case = { name: string; loop: "plant" | "closed" | "open"; points: { freq_hz: number; magnitude_db: number; phase_deg: number; coherence: number }[]; found: Record<string, number | null> };

function marked(item: Case): Record<string, number | null> {
  const response = responseOf(item.points);
  if (item.loop === "plant") return resonances(response);
  if (item.loop === "open") return margins(response);
  return { bandwidth_hz: bandwidth(response) };
}

describe("the shared marker cases", () => {
  for (const item of cases as unknown as Case[]) {
    it(item.name, () => {
      const got = marked(item);
      for (const [key, value] of Object.entries(got)) {
        const expected = item.found[key];
        expect(expected, key).not.toBeUndefined();
        if (expected === null) expect(value, key).toBeNull();
        else expect(value! / expected, key).toBeCloseTo(1, 9);
      }
    });
  }
});
