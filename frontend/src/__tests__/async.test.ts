import { afterEach, describe, expect, it, vi } from "vitest";
import { debounced, loader } from "../lib/async";
import { Scope, state } from "../lib/dom";

/** Let pending promise callbacks run. */
const settled = () => new Promise((resolve) => setTimeout(resolve, 0));

afterEach(() => vi.useRealTimers());

describe("loader", () => {
  it("loads again when an input changes and keeps only the latest answer", async () => {
    const scope = new Scope();
    const axis = state("X");
    const answers = new Map<string, (value: string) => void>();
    const loaded = loader(scope, () => axis.val, (name) => new Promise<string>((resolve) => answers.set(name, resolve)));
    expect(loaded.val.status).toBe("loading");
    await settled();
    axis.val = "Y";
    await settled();
    answers.get("Y")!("values of Y");
    await settled();
    answers.get("X")!("values of X"); // the old request answers last: dropped
    await settled();
    expect(loaded.val).toEqual({ status: "ready", value: "values of Y" });
  });

  it("reports a failure, and a state read by the load itself does not trigger a reload", async () => {
    const scope = new Scope();
    const other = state(1);
    let calls = 0;
    const loaded = loader(scope, () => "key", async () => {
      calls += other.val;
      throw new Error("no answer");
    });
    await settled();
    expect(loaded.val.status).toBe("failed");
    other.val = 2;
    await settled();
    expect(calls).toBe(1);
  });

  it("stops with its scope", async () => {
    const scope = new Scope();
    const input = state(0);
    const seen: number[] = [];
    loader(scope, () => input.val, async (value) => void seen.push(value));
    await settled();
    scope.dispose();
    input.val = 1;
    await settled();
    expect(seen).toEqual([0]);
  });
});

describe("debounced", () => {
  it("follows the source once it stopped changing", () => {
    vi.useFakeTimers();
    const scope = new Scope();
    const text = state("");
    const quiet = debounced(scope, text, 150);
    text.val = "K";
    vi.advanceTimersByTime(100);
    text.val = "KP";
    vi.advanceTimersByTime(100);
    expect(quiet.val).toBe("");
    vi.advanceTimersByTime(60);
    expect(quiet.val).toBe("KP");
    scope.dispose();
    text.val = "KPv";
    vi.advanceTimersByTime(500);
    expect(quiet.val).toBe("KP");
  });
});
