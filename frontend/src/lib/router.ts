/**
 * URL ⇄ route. Every page has its own URL (deep links, browser history); the server answers every non-API path
 * with index.html, and this module turns the path back into the page to show.
 */

export const AXIS_VIEWS = ["dashboard", "parameters", "commissioning", "backup", "scope", "current-loop", "phasing", "tuning", "bode", "sequences", "io"] as const;
export type AxisView = (typeof AXIS_VIEWS)[number];

export type Route =
  | { page: "home" }
  | { page: "project"; project: string }
  | { page: "compare"; project: string }
  | { page: "axis"; project: string; axis: string; view: AxisView }
  | { page: "bus" }
  | { page: "terminal" }
  | { page: "dictionaries" }
  | { page: "dictionary"; device: string }
  | { page: "motors" }
  | { page: "audit" }
  | { page: "login" }
  | { page: "setup" }
  | { page: "not-found"; path: string };

/** Route plus its query parameters (`?q=KPv&group=Servo%20Loops` on the parameter pages). */
export interface Location {
  route: Route;
  query: Record<string, string>;
}

export function parsePath(pathname: string, search = ""): Location {
  const parts = pathname.split("/").filter((part) => part !== "").map(decodeURIComponent);
  const query = Object.fromEntries(new URLSearchParams(search));
  return { route: matchParts(parts, pathname), query };
}

function matchParts(parts: string[], pathname: string): Route {
  const [first, second, third, fourth, fifth, ...rest] = parts;
  if (parts.length === 0) return { page: "home" };
  if (first === "projects" && second !== undefined) {
    if (parts.length === 2) return { page: "project", project: second };
    if (parts.length === 3 && third === "compare") return { page: "compare", project: second };
    if (third === "axes" && fourth !== undefined && rest.length === 0) {
      const view = (fifth ?? "dashboard") as AxisView;
      if (AXIS_VIEWS.includes(view)) return { page: "axis", project: second, axis: fourth, view };
    }
  }
  if (parts.length === 1 && first === "projects") return { page: "home" };
  if (parts.length === 1 && (first === "login" || first === "setup")) return { page: first };
  if (parts.length === 1 && (first === "bus" || first === "terminal" || first === "motors" || first === "dictionaries" || first === "audit")) {
    return { page: first };
  }
  if (parts.length === 2 && first === "dictionaries") return { page: "dictionary", device: second };
  return { page: "not-found", path: pathname };
}

export function buildPath(route: Route, query: Record<string, string | undefined> = {}): string {
  const path = pathOf(route);
  const params = new URLSearchParams();
  for (const [key, value] of Object.entries(query)) if (value) params.set(key, value);
  const search = params.toString();
  return search ? `${path}?${search}` : path;
}

function pathOf(route: Route): string {
  const e = encodeURIComponent;
  switch (route.page) {
    case "home":
      return "/";
    case "project":
      return `/projects/${e(route.project)}`;
    case "compare":
      return `/projects/${e(route.project)}/compare`;
    case "axis":
      return `/projects/${e(route.project)}/axes/${e(route.axis)}${route.view === "dashboard" ? "" : "/" + route.view}`;
    case "dictionary":
      return `/dictionaries/${e(route.device)}`;
    case "not-found":
      return route.path;
    default:
      return `/${route.page}`;
  }
}

/** Same page (ignoring query)? Lets the app update a page in place instead of rebuilding it. */
export function samePage(a: Route, b: Route): boolean {
  return pathOf(a) === pathOf(b);
}
