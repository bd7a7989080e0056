import { afterEach, describe, expect, it, vi } from "vitest";
import { App } from "../app";
import type { Project } from "../client/api";
import { runAction } from "../shortcuts";

const axis = (name: string, node: number) => ({ name, device: "xtrapulspac", node_id: node, bus: "sim", description: "", motor: "", application: "" });
const demo: Project = { name: "demo", description: "", revision: "1", buses: [], axes: [axis("X", 1), axis("Y", 2), axis("Z", 3)] };

afterEach(() => {
  vi.unstubAllGlobals();
  history.replaceState(null, "", "/");
});

describe("shortcuts", () => {
  it("[ and ] step through the project's axes on the same view, wrapping around", () => {
    vi.stubGlobal("fetch", vi.fn(async () => Response.json({ detail: "not in this test" }, { status: 404 })));
    history.replaceState(null, "", "/projects/demo/axes/Z/backup");
    const app = new App(document.createElement("div"));
    app.projects.val = [demo];
    expect(runAction(app, "next-axis")).toBe(true);
    expect(window.location.pathname).toBe("/projects/demo/axes/X/backup");
    expect(runAction(app, "previous-axis")).toBe(true);
    expect(window.location.pathname).toBe("/projects/demo/axes/Z/backup");
    expect(app.here.val.route).toMatchObject({ page: "axis", axis: "Z", view: "backup" });
  });

  it("g p opens the parameters of the first axis when no axis is shown; ] does nothing there", () => {
    vi.stubGlobal("fetch", vi.fn(async () => Response.json({ detail: "not in this test" }, { status: 404 })));
    const app = new App(document.createElement("div"));
    app.projects.val = [{ ...demo, name: "empty", axes: [] }, demo];
    expect(runAction(app, "next-axis")).toBe(false);
    expect(runAction(app, "go-parameters")).toBe(true);
    expect(window.location.pathname).toBe("/projects/demo/axes/X/parameters");
    expect(runAction(app, "unknown")).toBe(false);
  });

  it("g l, g f and g u open the current loop, phasing and auto-tuning of the axis shown", () => {
    vi.stubGlobal("fetch", vi.fn(async () => Response.json({ detail: "not in this test" }, { status: 404 })));
    history.replaceState(null, "", "/projects/demo/axes/Y/dashboard");
    const app = new App(document.createElement("div"));
    app.projects.val = [demo];
    for (const [action, view] of [["go-current-loop", "current-loop"], ["go-phasing", "phasing"], ["go-tuning", "tuning"]]) {
      expect(runAction(app, action)).toBe(true);
      expect(window.location.pathname).toBe(`/projects/demo/axes/Y/${view}`);
    }
  });
});
