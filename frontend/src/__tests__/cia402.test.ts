import { describe, expect, it } from "vitest";
import { allowedTransitions, decodeState } from "../lib/cia402";
import { BINDINGS, KeyMatcher, SEQUENCE_TIMEOUT_MS } from "../lib/keys";

describe("CiA 402 state", () => {
  it("decodes the manual's enable sequence status words (L3102-3126)", () => {
    expect(decodeState(0x0240)).toBe("switch_on_disabled");
    expect(decodeState(0x0221)).toBe("ready_to_switch_on");
    expect(decodeState(0x0223)).toBe("switched_on");
    expect(decodeState(0x0227)).toBe("operation_enabled");
    expect(decodeState(0x0207)).toBe("quick_stop_active");
    expect(decodeState(0x0208)).toBe("fault");
    expect(decodeState(0x020f)).toBe("fault_reaction_active");
    expect(decodeState(0x0000)).toBe("not_ready_to_switch_on");
  });

  it("offers only the transitions allowed in each state", () => {
    expect(allowedTransitions("switch_on_disabled").map((t) => t.command)).toEqual(["shutdown"]);
    expect(allowedTransitions("switched_on").map((t) => t.command)).toContain("enable_operation");
    expect(allowedTransitions("fault").map((t) => t.command)).toEqual(["fault_reset"]);
    expect(allowedTransitions("operation_enabled").map((t) => t.command)).not.toContain("enable_operation");
  });
});

describe("key sequences", () => {
  it("matches single keys and two-key sequences", () => {
    const matcher = new KeyMatcher();
    expect(matcher.feed("/", 0)).toBe("focus-search");
    expect(matcher.feed("g", 0)).toBeNull();
    expect(matcher.feed("d", 100)).toBe("go-dashboard");
    expect(matcher.feed("?", 200)).toBe("help");
  });

  it("drops a stale prefix and restarts on a wrong second key", () => {
    const matcher = new KeyMatcher();
    matcher.feed("g", 0);
    expect(matcher.feed("d", SEQUENCE_TIMEOUT_MS + 1)).toBeNull();
    matcher.feed("g", 5000);
    expect(matcher.feed("/", 5100)).toBe("focus-search");
    expect(matcher.feed("x", 5200)).toBeNull();
  });

  it("has no binding that shadows another", () => {
    const keys = BINDINGS.map((binding) => binding.keys);
    expect(new Set(keys).size).toBe(keys.length);
    for (const key of keys) expect(keys.some((other) => other.startsWith(key + " "))).toBe(key === "g" ? true : false);
  });
});
