import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { HoldToRun, KEEPALIVE_MS, type PageView } from "../client/motion";
import { holdButton } from "../components/motion/hold-button";
import { QuickMotion, homingChoice, laterMotion, motionText } from "../components/motion/model";
import { motionPanel } from "../components/motion/motion-panel";
import { Scope, state } from "../lib/dom";

interface FakePage {
  shown: boolean;
  hasFocus: boolean;
  fire(event: string): void;
  view: PageView;
}

/** A page whose visibility and focus the test sets, firing the listeners as a browser would. */
function fakePage(): FakePage {
  const listeners = new Map<string, Set<() => void>>();
  const page: FakePage = {
    shown: true,
    hasFocus: true,
    fire(event) {
      for (const listener of listeners.get(event) ?? []) listener();
    },
    view: {
      visible: () => page.shown,
      focused: () => page.hasFocus,
      on: (event, listener) => {
        if (!listeners.has(event)) listeners.set(event, new Set());
        listeners.get(event)!.add(listener);
        return () => listeners.get(event)!.delete(listener);
      },
    },
  };
  return page;
}

describe("hold-to-run keepalives", () => {
  beforeEach(() => vi.useFakeTimers());
  afterEach(() => vi.useRealTimers());

  function holding() {
    const sent: Record<string, unknown>[] = [];
    const page = fakePage();
    const lost = vi.fn();
    const hold = new HoldToRun({ send: (message) => (sent.push(message), true) }, () => "sim", 3, lost, page.view);
    return { sent, page, lost, hold };
  }

  it("sends one at once and one every period while held, and none after the end", () => {
    const { sent, hold } = holding();
    expect(hold.start()).toBe(true);
    expect(sent).toEqual([{ type: "keepalive", bus: "sim", node: 3 }]);
    vi.advanceTimersByTime(KEEPALIVE_MS * 4);
    expect(sent).toHaveLength(5);
    hold.end();
    vi.advanceTimersByTime(KEEPALIVE_MS * 4);
    expect(sent).toHaveLength(5);
  });

  it("does not start in a hidden or unfocused tab", () => {
    const { sent, page, hold } = holding();
    page.hasFocus = false;
    expect(hold.start()).toBe(false);
    expect(sent).toHaveLength(0);
  });

  it("stops at once when the tab loses focus or is hidden, and says so", () => {
    const { sent, page, lost, hold } = holding();
    hold.start();
    page.hasFocus = false;
    page.fire("blur");
    expect(lost).toHaveBeenCalledOnce();
    vi.advanceTimersByTime(KEEPALIVE_MS * 4);
    expect(sent).toHaveLength(1);
    page.hasFocus = true;
    hold.start();
    page.shown = false; // hidden without an event: the next period notices
    vi.advanceTimersByTime(KEEPALIVE_MS);
    expect(lost).toHaveBeenCalledTimes(2);
    expect(hold.holding).toBe(false);
  });
});

describe("hold button", () => {
  it("presses once on pointer down or Space, and releases on up", () => {
    const onPress = vi.fn();
    const onRelease = vi.fn();
    const button = holdButton({ label: "Hold", testid: "b", title: "", disabled: false, onPress, onRelease });
    button.dispatchEvent(new KeyboardEvent("keydown", { key: " " }));
    button.dispatchEvent(new KeyboardEvent("keydown", { key: " ", repeat: true }));
    expect(onPress).toHaveBeenCalledOnce();
    button.dispatchEvent(new KeyboardEvent("keyup", { key: " " }));
    expect(onRelease).toHaveBeenCalledOnce();
    button.dispatchEvent(new Event("pointercancel"));
    expect(onRelease).toHaveBeenCalledOnce(); // nothing held any more
  });
});

describe("motion status line", () => {
  it("says what the motion did and why it stopped", () => {
    expect(motionText(null)).toBe("No motion yet");
    const motion = {
      motion: "m1", bus: "sim", node: 1, kind: "jog" as const, state: "stopped" as const, position: 512,
      reason: "hold-to-run: no keepalive from client c for 104 ms",
    };
    expect(motionText(motion)).toBe("Jog stopped · position 512 — hold-to-run: no keepalive from client c for 104 ms");
  });
});

describe("the motion kept when answers and events cross", () => {
  const base = { motion: "m7", bus: "sim", node: 2, kind: "home" as const, reason: null };
  const running = { ...base, state: "running" as const, position: null };
  const done = { ...base, state: "done" as const, position: null };
  const read = { ...base, state: "done" as const, position: 4096 };

  it("keeps the end when the start's answer arrives after the end's event", () => {
    expect(laterMotion(done, running)).toBe(done);
    expect(laterMotion(read, done)).toBe(read);
  });

  it("takes every later state, and any other motion", () => {
    expect(laterMotion(running, done)).toBe(done);
    expect(laterMotion(done, read)).toBe(read);
    const next = { ...running, motion: "m8" };
    expect(laterMotion(read, next)).toBe(next);
    expect(laterMotion(read, null)).toBeNull();
  });

  it("keeps an ended motion when a stop that found nothing running answers after its event", () => {
    const nothingRunning = { motion: null, bus: "sim", node: 2, state: "stopped" as const, reason: "stopped by local" };
    expect(laterMotion(done, nothingRunning)).toBe(done);
    expect(laterMotion(running, nothingRunning)).toBe(nothingRunning);
    expect(laterMotion(null, nothingRunning)).toBe(nothingRunning);
  });
});

describe("the homing method shown and started", () => {
  const ttapro = [{ method: 128, description: "the current position (no search)" }, { method: 160, description: "marker pulse" }];

  it("keeps the picked method the device has, else takes the device's first", () => {
    expect(homingChoice([], "35")).toBe("35");
    expect(homingChoice([{ method: 1 }, { method: 35 }], "35")).toBe("35");
    expect(homingChoice(ttapro, "35")).toBe("128");
  });

  it("selects a TTA-PRO's first configuration with its description once the methods arrive", () => {
    const scope = new Scope();
    const model = new QuickMotion({ bus: "pb", node: 5, device: "ttapro", live: { on: () => () => undefined, send: () => true }, scope });
    const element = motionPanel({ model, armed: state(true), heldElsewhere: state(false), busy: state(false), onArm: vi.fn(), onRelease: vi.fn() });
    const select = element.querySelector<HTMLSelectElement>('[data-testid="homing-method"]')!;
    expect(element.textContent).not.toMatch(/\((PV|PP|HM)\)/); // no CiA 402 modes on a TTA-PRO
    model.methods.val = ttapro;
    expect(select.value).toBe("128");
    expect(element.querySelector('[data-testid="homing-description"]')!.textContent).toBe("the current position (no search)");
    select.value = "160";
    select.dispatchEvent(new Event("change"));
    expect(element.querySelector('[data-testid="homing-description"]')!.textContent).toBe("marker pulse");
    scope.dispose();
  });
});
