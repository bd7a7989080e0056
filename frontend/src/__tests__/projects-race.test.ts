import { afterEach, describe, expect, it, vi } from "vitest";
import { App } from "../app";
import type { Project } from "../client/api";

const project = (name: string): Project => ({ name, description: "", revision: "1", buses: [], axes: [] });

afterEach(() => {
  vi.unstubAllGlobals();
});

/** A server whose project list answers when the test says (a slow server), the rest at once. */
function slowListServer(names: string[]) {
  const held: (() => void)[] = [];
  vi.stubGlobal("fetch", vi.fn(async (url: string) => {
    const path = new URL(url, "http://localhost").pathname;
    if (path === "/api/projects") {
      const answer = [...names].map((name) => ({ name, description: "", axes: 0, revision: "1" }));
      await new Promise<void>((resolve) => held.push(resolve));
      return Response.json(answer);
    }
    const name = decodeURIComponent(path.replace("/api/projects/", ""));
    if (path.startsWith("/api/projects/") && names.includes(name)) return Response.json(project(name));
    return Response.json({ detail: "not in this test" }, { status: 404 });
  }));
  const release = async () => {
    while (held.length === 0) await new Promise((resolve) => setTimeout(resolve, 1));
    held.shift()!();
  };
  return { names, release };
}

describe("the projects in the tree", () => {
  it("keeps a project created while the page's first list was on its way", async () => {
    const server = slowListServer(["demo"]);
    const app = new App(document.createElement("div"));
    const refreshed = app.refreshProjects();
    await new Promise((resolve) => setTimeout(resolve, 5)); // the first list is asked for: it holds "demo" only
    server.names.push("line2");
    app.updateProject(project("line2")); // created by the user meanwhile
    await server.release(); // the stale list arrives …
    await server.release(); // … and is fetched again, with line2
    await refreshed;
    expect(app.projectsLoaded().map((p) => p.name)).toEqual(["demo", "line2"]);
  });
});
