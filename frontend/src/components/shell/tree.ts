/**
 * The project tree: projects → axes, each axis with its live state (bound to the live hub's state of that axis),
 * then the tools. The entry of the page shown is marked active (bound to the app's location).
 */

import type { App } from "../../app";
import type { AxisConfig, Project } from "../../client/api";
import { axisStateText } from "../../client/live";
import { h } from "../../lib/dom";
import { buildPath, samePage, type Route } from "../../lib/router";

const TOOLS: [Route, string][] = [
  [{ page: "bus" }, "Bus and scan"],
  [{ page: "terminal" }, "Dialog terminal"],
  [{ page: "dictionaries" }, "Object dictionaries"],
  [{ page: "motors" }, "Motor catalog"],
  [{ page: "audit" }, "Audit log"],
];

export function projectTree(app: App): HTMLElement {
  return h("nav", { class: "tree", "aria-label": "Projects and axes", "data-testid": "project-tree" }, () => {
    const error = app.projectsError.val;
    if (error !== null) return h("div", { class: "message error" }, error);
    const list = app.projects.val;
    return [
      h("div", { class: "side-title" }, "Projects", h("a", { href: "/", title: "Create or open a project" }, "Manage")),
      list.length === 0 ? h("div", { class: "empty" }, "No projects yet") : list.map((project) => projectEntries(app, project)),
      h("div", { class: "side-title" }, "Tools"),
      TOOLS.map(([target, label]) => h("a", { href: buildPath(target), class: () => (samePage(target, app.here.val.route) ? "active" : "") }, label)),
    ];
  });
}

/** The project being shown and the axis being shown (null when the page is not one of theirs). */
function shown(app: App): { project: string | null; axis: string | null } {
  const route = app.here.val.route;
  const project = route.page === "axis" || route.page === "project" || route.page === "compare" ? route.project : null;
  return { project, axis: route.page === "axis" ? route.axis : null };
}

function projectEntries(app: App, project: Project): Node[] {
  const link = h("a", {
    href: buildPath({ page: "project", project: project.name }),
    class: () => {
      const current = shown(app);
      return current.project === project.name && !current.axis ? "active" : "";
    },
    "data-testid": `tree-project-${project.name}`,
  }, h("span", null, "▾"), h("strong", null, project.name));
  return [link, ...project.axes.map((axis) => axisEntry(app, project, axis))];
}

function axisEntry(app: App, project: Project, axis: AxisConfig): HTMLElement {
  const status = app.live.axisState(axis.bus, axis.node_id);
  const text = () => axisStateText(status.val);
  return h("a", {
    href: () => {
      const route = app.here.val.route;
      return buildPath({ page: "axis", project: project.name, axis: axis.name, view: route.page === "axis" ? route.view : "dashboard" });
    },
    class: () => {
      const current = shown(app);
      return `axis ${current.project === project.name && current.axis === axis.name ? "active" : ""}`;
    },
    "data-testid": `tree-axis-${axis.name}`,
    title: () => `${axis.device}, node ${axis.node_id} on bus ${axis.bus}: ${text().text}`,
  },
  h("span", { class: () => `dot ${text().tone}` }),
  h("span", null, axis.name),
  h("span", { class: () => `state ${text().tone}`, "data-testid": `tree-state-${axis.name}` }, () => text().text));
}
