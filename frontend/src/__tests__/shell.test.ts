import { afterEach, describe, expect, it } from "vitest";
import { App } from "../app";
import type { Project } from "../client/api";
import { learnBuses, serverBus } from "../client/drives";
import { busStatus, serverStatus, userStatus } from "../components/shell/topbar";
import { projectTree } from "../components/shell/tree";
import { h, state } from "../lib/dom";
import { parsePath } from "../lib/router";

const demo: Project = {
  name: "demo", description: "", revision: "1", buses: [{ name: "sim", interface: "sim", bitrate: null }],
  axes: [
    { name: "X", device: "xtrapulspac", node_id: 1, bus: "sim", description: "", motor: "", application: "" },
    { name: "Y", device: "xtrapulspac", node_id: 2, bus: "sim", description: "", motor: "", application: "" },
  ],
};

const testid = (root: Element, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`)!;

afterEach(() => {
  document.body.textContent = "";
  history.replaceState(null, "", "/");
});

describe("project tree", () => {
  it("shows each axis's live state as it changes, without rebuilding the entry", () => {
    const app = new App(document.createElement("div"));
    app.projects.val = [demo];
    const tree = projectTree(app);
    const entry = testid(tree, "tree-axis-X");
    expect(testid(tree, "tree-state-X").textContent).toBe("…");
    app.live.updateAxis("sim", 1, { online: true, statusword: 0x0240 });
    expect(testid(tree, "tree-state-X").textContent).toBe("Switch on disabled");
    app.live.updateAxis("sim", 1, { statusword: 0x0208, faultText: "I²t error" });
    expect(testid(tree, "tree-state-X").textContent).toBe("Fault: I²t error");
    expect(testid(tree, "tree-state-X").className).toBe("state bad");
    expect(entry.title).toBe("xtrapulspac, node 1 on bus sim: Fault: I²t error");
    expect(testid(tree, "tree-axis-X")).toBe(entry);
    expect(testid(tree, "tree-state-Y").textContent).toBe("…");
  });

  it("marks the entry of the page shown and keeps the axis view in the links", () => {
    const app = new App(document.createElement("div"));
    app.projects.val = [demo];
    const tree = projectTree(app);
    app.here.val = parsePath("/projects/demo/axes/Y/backup");
    expect(testid(tree, "tree-axis-Y").classList.contains("active")).toBe(true);
    expect(testid(tree, "tree-axis-X").classList.contains("active")).toBe(false);
    expect(testid(tree, "tree-project-demo").className).toBe("");
    expect(testid(tree, "tree-axis-X").getAttribute("href")).toBe("/projects/demo/axes/X/backup");
    app.here.val = parsePath("/projects/demo");
    expect(testid(tree, "tree-project-demo").className).toBe("active");
    expect(testid(tree, "tree-axis-X").getAttribute("href")).toBe("/projects/demo/axes/X");
    app.here.val = parsePath("/terminal");
    expect([...tree.querySelectorAll("a.active")].map((a) => a.textContent)).toEqual(["Dialog terminal"]);
  });

  it("shows why the projects could not be loaded instead of the list", () => {
    const app = new App(document.createElement("div"));
    const tree = projectTree(app);
    expect(tree.textContent).toContain("No projects yet");
    app.projectsError.val = "HTTP 500";
    expect(tree.textContent).toBe("HTTP 500");
  });
});

describe("top bar", () => {
  it("binds the bus, user and server pills to their states", () => {
    const app = new App(document.createElement("div"));
    const buses = busStatus(app.live);
    const user = userStatus(app.live);
    expect(buses.textContent).toBe("No bus connected");
    app.live.setBuses([{ name: "sim", state: "connected" }, { name: "can0", state: "disconnected" }]);
    expect(buses.textContent).toBe("sim: connected · can0: disconnected");
    expect(buses.querySelector(".dot")!.className).toBe("dot warn");
    expect(user.textContent).toBe("not logged in");
    app.live.setUser({ name: "local", level: "administrator" });
    expect(user.textContent).toBe("local · administrator"); // password-less: nobody to log out
    app.live.setUser({ name: "olga", level: "operator" });
    expect(user.textContent).toBe("olga · operatorLog out");
    const server = state({ state: "connecting" as "connecting" | "online" | "offline", text: "Connecting to server…" });
    const pill = serverStatus(server);
    server.val = { state: "online", text: "Server online · v1" };
    expect(pill.dataset.state).toBe("online");
    expect(pill.textContent).toBe("Server online · v1");
  });
});

describe("bus mapping", () => {
  it("is a state: a binding that shows the server bus follows a new mapping", () => {
    const cell = h("span", null, () => serverBus("line1"));
    learnBuses([{ id: "bus0", spec: "sim", kind: "sim", connected: true, error: null, nodes: [] }], [{ name: "line1", interface: "sim" }]);
    expect(cell.textContent).toBe("bus0");
    learnBuses([], []);
    expect(cell.textContent).toBe("line1");
  });
});
