import { describe, expect, it } from "vitest";
import { buildPath, parsePath, type Route } from "../lib/router";

describe("router", () => {
  it("parses every page's URL", () => {
    expect(parsePath("/").route).toEqual({ page: "home" });
    expect(parsePath("/projects/demo").route).toEqual({ page: "project", project: "demo" });
    expect(parsePath("/projects/demo/compare").route).toEqual({ page: "compare", project: "demo" });
    expect(parsePath("/projects/demo/axes/X1").route).toEqual({ page: "axis", project: "demo", axis: "X1", view: "dashboard" });
    expect(parsePath("/projects/demo/axes/X1/parameters", "?q=KPv").route).toEqual({
      page: "axis", project: "demo", axis: "X1", view: "parameters",
    });
    expect(parsePath("/bus").route).toEqual({ page: "bus" });
    expect(parsePath("/dictionaries/xtrapulspac").route).toEqual({ page: "dictionary", device: "xtrapulspac" });
    expect(parsePath("/projects/demo/axes/X1/nonsense").route.page).toBe("not-found");
  });

  it("keeps query parameters", () => {
    expect(parsePath("/projects/p/axes/a/parameters", "?q=KPv&group=Servo%20Loops").query).toEqual({
      q: "KPv", group: "Servo Loops",
    });
  });

  it("round-trips routes, encoding names with spaces and slashes", () => {
    const routes: Route[] = [
      { page: "home" },
      { page: "project", project: "line 2/press" },
      { page: "axis", project: "demo", axis: "axis 1", view: "dashboard" },
      { page: "axis", project: "demo", axis: "Z", view: "commissioning" },
      { page: "compare", project: "demo" },
      { page: "terminal" },
      { page: "motors" },
    ];
    for (const route of routes) expect(parsePath(buildPath(route)).route).toEqual(route);
    expect(buildPath({ page: "axis", project: "demo", axis: "X", view: "parameters" }, { q: "KPv", group: "" })).toBe(
      "/projects/demo/axes/X/parameters?q=KPv",
    );
  });
});
