import { describe, expect, it } from "vitest";
import { Scope, derive, effect, h, state } from "../lib/dom";

describe("reactive DOM binding", () => {
  it("binds an attribute and a text child to a state", () => {
    const count = state(1);
    const element = h("span", { class: () => (count.val > 1 ? "many" : "one") }, () => `n=${count.val}`);
    expect(element.className).toBe("one");
    expect(element.textContent).toBe("n=1");
    count.val = 3;
    expect(element.className).toBe("many");
    expect(element.textContent).toBe("n=3");
  });

  it("replaces a bound list in place, leaving its siblings alone", () => {
    const items = state(["a", "b"]);
    const before = h("i", null, "x");
    const list = h("ul", null, before, () => items.val.map((item) => h("li", null, item)), h("b", null, "end"));
    expect(list.textContent).toBe("xabend");
    items.val = ["c"];
    expect(list.textContent).toBe("xcend");
    expect(list.firstElementChild).toBe(before);
  });

  it("re-computes a derived state and re-tracks only the branch taken", () => {
    const flag = state(true);
    const left = state("L");
    const right = state("R");
    let runs = 0;
    const chosen = derive(() => {
      runs += 1;
      return flag.val ? left.val : right.val;
    });
    expect(chosen.val).toBe("L");
    right.val = "R2";
    expect(runs).toBe(1);
    flag.val = false;
    expect(chosen.val).toBe("R2");
    left.val = "L2";
    expect(runs).toBe(2);
  });

  it("stops an effect when its scope is disposed", () => {
    const value = state(0);
    const seen: number[] = [];
    const scope = new Scope();
    scope.effect(() => void seen.push(value.val));
    value.val = 1;
    scope.dispose();
    value.val = 2;
    expect(seen).toEqual([0, 1]);
    const stop = effect(() => void seen.push(value.val * 10));
    stop();
    value.val = 3;
    expect(seen).toEqual([0, 1, 20]);
  });

  it("sets boolean properties and omits false attributes", () => {
    const busy = state(false);
    const button = h("button", { disabled: busy, title: () => (busy.val ? "busy" : false) });
    expect(button.disabled).toBe(false);
    expect(button.hasAttribute("title")).toBe(false);
    busy.val = true;
    expect(button.disabled).toBe(true);
    expect(button.getAttribute("title")).toBe("busy");
  });
});
