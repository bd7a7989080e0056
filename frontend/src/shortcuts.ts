/** Keyboard shortcuts of the shell (the table is `lib/keys.ts`, shown by `?`): what each action does. */

import type { App } from "./app";
import { toggleHelp } from "./components/help";
import { toggleTheme } from "./components/theme";
import { BINDINGS, KeyMatcher } from "./lib/keys";
import type { AxisView, Route } from "./lib/router";

const PAGES: Record<string, Route> = {
  "go-home": { page: "home" },
  "go-bus": { page: "bus" },
  "go-terminal": { page: "terminal" },
  "go-dictionaries": { page: "dictionaries" },
  "go-motors": { page: "motors" },
};

const AXIS_VIEWS: Record<string, AxisView> = {
  "go-dashboard": "dashboard",
  "go-parameters": "parameters",
  "go-commissioning": "commissioning",
  "go-backup": "backup",
  "go-scope": "scope",
  "go-current-loop": "current-loop",
  "go-phasing": "phasing",
  "go-tuning": "tuning",
};

/** Listen to the keyboard: shortcuts are ignored while typing in a field, where Escape leaves the field. */
export function installShortcuts(app: App): void {
  const keys = new KeyMatcher(BINDINGS);
  document.addEventListener("keydown", (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey) return;
    const target = event.target as HTMLElement;
    if (target.closest?.("input, textarea, select, [contenteditable]") !== null) {
      if (event.key === "Escape") target.blur();
      return;
    }
    const action = keys.feed(event.key, performance.now());
    if (action && runAction(app, action)) event.preventDefault();
  });
}

/** Run one action; false when it does not apply here (the key then keeps its usual meaning). */
export function runAction(app: App, action: string): boolean {
  if (action === "focus-search") return app.focusSearch();
  if (action === "help") toggleHelp();
  else if (action === "toggle-theme") toggleTheme();
  else if (action in PAGES) app.navigate(PAGES[action]);
  else if (action in AXIS_VIEWS) goAxis(app, AXIS_VIEWS[action]);
  else if (action === "previous-axis" || action === "next-axis") return stepAxis(app, action === "next-axis" ? 1 : -1);
  else return app.pageShortcut(action);
  return true;
}

/** The view of the current axis, or of the first axis of the projects. */
function goAxis(app: App, view: AxisView): void {
  const route = app.location.route;
  const first = app.projectsLoaded().find((project) => project.axes.length > 0);
  const target = route.page === "axis" ? route : first ? { project: first.name, axis: first.axes[0].name } : null;
  if (target) app.navigate({ page: "axis", project: target.project, axis: target.axis, view });
}

/** The same view of the previous / next axis of the project, wrapping around. */
function stepAxis(app: App, step: number): boolean {
  const route = app.location.route;
  if (route.page !== "axis") return false;
  const project = app.projectsLoaded().find((p) => p.name === route.project);
  if (!project || project.axes.length === 0) return false;
  const position = project.axes.findIndex((axis) => axis.name === route.axis);
  const next = project.axes[(position + step + project.axes.length) % project.axes.length];
  app.navigate({ ...route, axis: next.name }, app.location.query);
  return true;
}
