import { describe, expect, it } from "vitest";
import { Scope, batch, derive, effect, h, state, untrack } from "../lib/dom";

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

  it("stops the bindings, effects and derived states created in a scope when it is disposed", () => {
    const value = state(1);
    const scope = new Scope();
    const seen: number[] = [];
    const element = scope.run(() => {
      const doubled = derive(() => value.val * 2);
      effect(() => void seen.push(doubled.val));
      return h("span", { title: () => `t${value.val}` }, () => `n=${value.val}`);
    });
    value.val = 2;
    expect([element.textContent, element.title, seen]).toEqual(["n=2", "t2", [2, 4]]);
    scope.dispose();
    value.val = 3;
    expect([element.textContent, element.title, seen]).toEqual(["n=2", "t2", [2, 4]]);
  });

  it("stops the bindings of a bound child's old content when the content is replaced", () => {
    const page = state("a");
    const label = state("x");
    let reads = 0;
    const element = h("div", null, () => {
      const current = page.val;
      return h("p", null, () => {
        reads += 1;
        return `${current}:${label.val}`;
      });
    });
    expect(element.textContent).toBe("a:x");
    page.val = "b";
    reads = 0;
    label.val = "y";
    // Only the binding of the current content runs: the old <p>'s is stopped, not left for the collector.
    expect(reads).toBe(1);
    expect(element.textContent).toBe("b:y");
  });

  it("untrack reads without making the caller depend on what it read", () => {
    const tracked = state(1);
    const ignored = state(10);
    let runs = 0;
    const sum = derive(() => {
      runs += 1;
      return tracked.val + untrack(() => ignored.val);
    });
    ignored.val = 20;
    expect([sum.val, runs]).toEqual([11, 1]);
    tracked.val = 2;
    expect([sum.val, runs]).toEqual([22, 2]);
  });

  it("batch runs each reader once, after all the changes", () => {
    const a = state(1);
    const b = state(2);
    const seen: number[] = [];
    effect(() => void seen.push(a.val + b.val));
    batch(() => {
      a.val = 10;
      b.val = 20;
      expect(seen).toEqual([3]);
    });
    expect(seen).toEqual([3, 30]);
  });

  it("selects a <select>'s bound value among its options, given after the value", () => {
    const choice = state("b");
    const select = h("select", { value: choice }, ["a", "b", "c"].map((value) => h("option", { value }, value)));
    expect(select.value).toBe("b");
    choice.val = "c";
    expect(select.value).toBe("c");
    expect(h("select", { value: "c" }, h("option", { value: "a" }), h("option", { value: "c" })).value).toBe("c");
  });
});
