/** The pages of one axis: header with device, node and live state, tabs, and the chosen view. */

import type { Page, PageContext } from "../app";
import { getDictionary, projects, type AxisConfig, type Project } from "../client/api";
import { h, Scope } from "../lib/dom";
import { forNode, type Dictionary } from "../lib/od";
import { buildPath, type AxisView } from "../lib/router";
import { axisTab, axisTabs } from "../lib/axis-tabs";
import { axisStateText } from "../client/live";
import { reportButton } from "../components/report/button";
import { backupView } from "./backup";
import { commissioningView } from "./commissioning";
import { dashboardView } from "./dashboard";
import { parametersView } from "./axisparams";
import { currentLoopView } from "./currentloop";
import { phasingView } from "./phasing";
import { ioView } from "./io";
import { sequencesView } from "./sequences";

export interface AxisContext {
  page: PageContext;
  project: Project;
  axis: AxisConfig;
  dictionary: Dictionary;
}

export interface AxisViewPage {
  element: HTMLElement;
  update?: Page["update"];
  dispose?(): void;
  focusSearch?(): boolean;
  /** A shortcut of the view (scope: arm, force, stop); false when it is not the view's. */
  shortcut?(action: string): boolean;
}

export async function axisPage(context: PageContext, projectName: string, axisName: string, view: AxisView): Promise<Page> {
  // The tree already knows the axis's device: fetch its dictionary while the project is fetched.
  const known = context.app.projectsLoaded().find((p) => p.name === projectName)?.axes.find((a) => a.name === axisName);
  const early = known ? getDictionary(known.device) : null;
  early?.catch(() => undefined);
  const project = await projects.get(projectName);
  const axis = project.axes.find((candidate) => candidate.name === axisName);
  if (!axis) {
    throw new Error(`Project ${projectName} has no axis "${axisName}" (axes: ${project.axes.map((a) => a.name).join(", ") || "none"}).`);
  }
  const shared = await (known?.device === axis.device && early ? early : getDictionary(axis.device));
  const dictionary = forNode(shared, axis.node_id);
  const axisContext: AxisContext = { page: context, project, axis, dictionary };
  const tabs = axisTabs(dictionary);
  const viewPage = await (!tabs.some((tab) => tab.view === view) ? unavailableView(dictionary, view)
    : view === "dashboard" ? dashboardView(axisContext)
    : view === "parameters" ? parametersView(axisContext)
      : view === "commissioning" ? commissioningView(axisContext)
        : view === "scope" ? import("./scope").then((module) => module.scopeView(axisContext)) // plotly only here
          : view === "current-loop" ? currentLoopView(axisContext)
            : view === "phasing" ? phasingView(axisContext)
              : view === "tuning" ? import("./tuning").then((module) => module.tuningView(axisContext)) // plots with plotly
                : view === "bode" ? import("./bode").then((module) => module.bodeView(axisContext)) // plotly only here
                : view === "sequences" ? sequencesView(axisContext)
                  : view === "io" ? ioView(axisContext)
                    : backupView(axisContext));

  // The header follows the live hub, which outlives the page: its binding is stopped with the page's scope.
  const scope = new Scope();
  const status = context.app.live.axisState(axis.bus, axis.node_id);
  const state = scope.run(() => h("span", { class: "pill", "data-testid": "axis-live-state" }, () => {
    const text = axisStateText(status.val);
    return [h("span", { class: `dot ${text.tone}` }), text.text];
  }));
  const nav = h("nav", { class: "tabs" }, tabs.map(({ view: key, label, keys }) => h("a", {
    href: buildPath({ page: "axis", project: project.name, axis: axis.name, view: key }),
    class: key === view ? "active" : "", title: keys ? `${label} (${keys})` : label, "data-testid": `tab-${key}`,
  }, label)));
  const head = h("div", { class: "page-head" },
    h("h1", { "data-testid": "axis-title" }, axis.name),
    h("span", { class: "muted" }, `${dictionary.product_name} · node ${axis.node_id} · bus ${axis.bus}${axis.motor ? ` · motor ${axis.motor}` : ""}`),
    state, reportButton(project.name, axis.name));
  const wrapper = h("div", { class: "page", style: { paddingBottom: "0", flex: "none" } }, head, nav);
  viewPage.element.style.flex = "1";
  return {
    title: `${axis.name} ${axisTab(view).label}`,
    crumbs: [h("a", { href: "/" }, "Projects"), " / ", h("a", { href: buildPath({ page: "project", project: project.name }) }, project.name), ` / ${axis.name}`],
    element: h("div", { style: { display: "flex", flexDirection: "column", flex: "1", minHeight: "0" } }, wrapper, viewPage.element),
    update: viewPage.update,
    focusSearch: viewPage.focusSearch,
    shortcut: viewPage.shortcut,
    dispose: () => {
      scope.dispose();
      viewPage.dispose?.();
    },
  };
}

/** A view the device cannot use (a link or a shortcut led here): say so instead of a page the server refuses. */
function unavailableView(dictionary: Dictionary, view: AxisView): AxisViewPage {
  return {
    element: h("div", { class: "page" }, h("div", { class: "message warn", "data-testid": "view-unavailable" },
      `${axisTab(view).label}: the ${dictionary.product_name} (${dictionary.fieldbus}) does not have it. Its tabs above are what it offers.`)),
  };
}
