/**
 * The application: shell (top bar, project tree, main area), client-side navigation with the History API,
 * keyboard shortcuts and theme. Pages are plain modules that build their element from a `PageContext`.
 */

import { getHealth, getMe, projects, type Project } from "./client/api";
import { errorText } from "./components/ui";
import { h, replaceChildren } from "./lib/dom";
import { BINDINGS, KeyMatcher } from "./lib/keys";
import { buildPath, parsePath, samePage, type AxisView, type Location, type Route } from "./lib/router";
import { LiveHub, axisStateText } from "./client/live";
import { showHelp, toggleHelp } from "./components/help";
import { applyTheme, storedTheme, toggleTheme } from "./components/theme";
import { mountPage } from "./pages";
import { driveApi, learnBuses } from "./client/drives";

/** Tree states come from events (`drive_state`, NMT, EMCY); only while the event socket is down are they polled. */
const TREE_FALLBACK_MS = 10000;
const APP_NAME = "Servo Studio";

export interface Page {
  element: HTMLElement;
  /** Title shown in the browser tab and the top bar. */
  title: string;
  crumbs?: (Node | string)[];
  /** Apply a query-only change in place; false to rebuild the page. */
  update?(location: Location): boolean;
  dispose?(): void;
  /** Focus the page's search field (shortcut `/`); false when the page has none. */
  focusSearch?(): boolean;
}

export interface PageContext {
  app: App;
  location: Location;
}

export class App {
  readonly live = new LiveHub();
  location: Location;
  private page: Page | null = null;
  private readonly main: HTMLElement;
  private readonly tree: HTMLElement;
  private readonly crumbs: HTMLElement;
  private readonly serverStatus: HTMLElement;
  private readonly busStatus: HTMLElement;
  private readonly userStatus: HTMLElement;
  private projectList: Project[] = [];
  private projectsKnown = false;
  private resolveProjects: () => void = () => undefined;
  /** Resolves once the project list was loaded (pages that offer axes wait for it). */
  readonly projectsReady = new Promise<void>((resolve) => (this.resolveProjects = resolve));
  private readonly keys = new KeyMatcher(BINDINGS);
  private renderToken = 0;

  constructor(root: HTMLElement) {
    applyTheme(storedTheme());
    this.serverStatus = h("span", { class: "pill server-status", "data-testid": "server-status" });
    this.busStatus = h("span", { class: "pill", "data-testid": "bus-status", title: "Buses of the communication server" });
    this.userStatus = h("span", { class: "pill", "data-testid": "user-status", title: "User and level" });
    this.crumbs = h("nav", { class: "crumbs", "aria-label": "Location" });
    this.tree = h("nav", { class: "tree", "aria-label": "Projects and axes", "data-testid": "project-tree" });
    this.main = h("main", { class: "main" });
    const layout = h(
      "div",
      { class: "layout" },
      h(
        "header",
        { class: "topbar" },
        h("a", { class: "brand", href: "/" }, "Servo Studio"),
        this.crumbs,
        h("span", { class: "spacer" }),
        this.busStatus,
        this.userStatus,
        this.serverStatus,
        h("button", { class: "small", title: "Switch theme (T)", "data-testid": "theme-toggle", onclick: () => toggleTheme() }, "Theme"),
        h("button", { class: "small", title: "Keyboard shortcuts (?)", onclick: () => showHelp() }, "?"),
      ),
      h("aside", { class: "sidebar" }, this.tree),
      this.main,
    );
    replaceChildren(root, layout);
    this.location = parsePath(window.location.pathname, window.location.search);
    document.addEventListener("click", (event) => this.onClick(event));
    document.addEventListener("keydown", (event) => this.onKey(event));
    window.addEventListener("popstate", () => this.show(parsePath(window.location.pathname, window.location.search)));
    this.live.onChange(() => {
      this.renderTree();
      this.renderBusStatus();
    });
  }

  async start(): Promise<void> {
    this.setServer("connecting");
    void this.refreshHealth();
    void getMe().then((user) => this.live.setUser(user), () => undefined);
    setInterval(() => void this.refreshHealth(), 10000);
    this.live.refreshAxis = async (axis) => {
      try {
        const state = await driveApi.state(axis.bus, axis.node_id);
        this.live.updateAxis(axis.bus, axis.node_id, { online: true, nmt: state.nmt_state, statusword: state.statusword });
      } catch {
        this.live.updateAxis(axis.bus, axis.node_id, { online: false });
      }
    };
    for (const type of ["bus_state", "bus_closed", "scan", "ws_open"]) this.live.on(type, () => void this.refreshBuses());
    for (const type of ["emcy", "bootup", "heartbeat_back"]) this.live.on(type, () => void this.live.refreshAxes());
    setInterval(() => {
      if (!this.live.connected() && document.visibilityState === "visible") void this.live.refreshAxes();
    }, TREE_FALLBACK_MS);
    this.live.start();
    this.render();
    await this.refreshProjects();
  }

  // ---- navigation ---------------------------------------------------------------------------------------------

  navigate(route: Route, query: Record<string, string | undefined> = {}, replace = false): void {
    const path = buildPath(route, query);
    if (replace) history.replaceState(null, "", path);
    else history.pushState(null, "", path);
    this.show(parsePath(window.location.pathname, window.location.search));
  }

  /** Change the query (search text, group) without a new history entry and without rebuilding the page. */
  replaceQuery(query: Record<string, string | undefined>): void {
    const path = buildPath(this.location.route, query);
    history.replaceState(null, "", path);
    this.location = parsePath(window.location.pathname, window.location.search);
  }

  private show(location: Location): void {
    const previous = this.location;
    this.location = location;
    if (this.page?.update && samePage(previous.route, location.route) && this.page.update(location)) return;
    this.render();
  }

  private render(): void {
    this.page?.dispose?.();
    this.page = null;
    const token = ++this.renderToken;
    const context: PageContext = { app: this, location: this.location };
    const loading = h("div", { class: "page" }, h("div", { class: "empty-state" }, "Loading…"));
    replaceChildren(this.main, loading);
    mountPage(context)
      .then((page) => {
        if (token !== this.renderToken) {
          page.dispose?.();
          return;
        }
        this.page = page;
        document.title = page.title === APP_NAME ? APP_NAME : `${page.title} · ${APP_NAME}`;
        replaceChildren(this.crumbs, ...(page.crumbs ?? [page.title]));
        replaceChildren(this.main, page.element);
        this.renderTree();
      })
      .catch((error) => {
        if (token !== this.renderToken) return;
        document.title = "Error · Servo Studio";
        replaceChildren(this.main, h("div", { class: "page" }, h("div", { class: "message error", "data-testid": "page-error" }, errorText(error))));
      });
  }

  private onClick(event: MouseEvent): void {
    if (event.defaultPrevented || event.button !== 0 || event.metaKey || event.ctrlKey || event.shiftKey || event.altKey) return;
    const link = (event.target as Element).closest?.("a");
    if (!link || link.target || link.hasAttribute("download")) return;
    const url = new URL(link.href, window.location.href);
    if (url.origin !== window.location.origin || url.pathname.startsWith("/api/") || url.pathname.startsWith("/docs")) return;
    event.preventDefault();
    history.pushState(null, "", url.pathname + url.search);
    this.show(parsePath(url.pathname, url.search));
  }

  // ---- shortcuts ----------------------------------------------------------------------------------------------

  private onKey(event: KeyboardEvent): void {
    if (event.ctrlKey || event.metaKey || event.altKey) return;
    const target = event.target as HTMLElement;
    const typing = target.closest?.("input, textarea, select, [contenteditable]") !== null;
    if (typing) {
      if (event.key === "Escape") target.blur();
      return;
    }
    const action = this.keys.feed(event.key, performance.now());
    if (action && this.runAction(action)) event.preventDefault();
  }

  private runAction(action: string): boolean {
    const route = this.location.route;
    const goAxis = (view: AxisView) => {
      const target = route.page === "axis" ? route : this.firstAxis();
      if (target) this.navigate({ page: "axis", project: target.project, axis: target.axis, view });
    };
    switch (action) {
      case "focus-search":
        return this.page?.focusSearch?.() ?? false;
      case "help":
        toggleHelp();
        return true;
      case "toggle-theme":
        toggleTheme();
        return true;
      case "go-home":
        this.navigate({ page: "home" });
        return true;
      case "go-dashboard":
        goAxis("dashboard");
        return true;
      case "go-parameters":
        goAxis("parameters");
        return true;
      case "go-commissioning":
        goAxis("commissioning");
        return true;
      case "go-backup":
        goAxis("backup");
        return true;
      case "go-bus":
        this.navigate({ page: "bus" });
        return true;
      case "go-terminal":
        this.navigate({ page: "terminal" });
        return true;
      case "go-dictionaries":
        this.navigate({ page: "dictionaries" });
        return true;
      case "go-motors":
        this.navigate({ page: "motors" });
        return true;
      case "previous-axis":
      case "next-axis":
        return this.stepAxis(action === "next-axis" ? 1 : -1);
      default:
        return false;
    }
  }

  private firstAxis(): { project: string; axis: string } | null {
    const project = this.projectList.find((p) => p.axes.length > 0);
    return project ? { project: project.name, axis: project.axes[0].name } : null;
  }

  private stepAxis(step: number): boolean {
    const route = this.location.route;
    if (route.page !== "axis") return false;
    const project = this.projectList.find((p) => p.name === route.project);
    if (!project || project.axes.length === 0) return false;
    const position = project.axes.findIndex((axis) => axis.name === route.axis);
    const next = project.axes[(position + step + project.axes.length) % project.axes.length];
    this.navigate({ ...route, axis: next.name }, this.location.query);
    return true;
  }

  // ---- project tree -------------------------------------------------------------------------------------------

  /** Reload the projects shown in the tree (after create, rename, add axis…). */
  async refreshProjects(): Promise<void> {
    try {
      const summaries = await projects.list();
      this.projectList = await Promise.all(summaries.map((summary) => projects.get(summary.name)));
    } catch (error) {
      this.projectList = [];
      this.projectsKnown = true;
      replaceChildren(this.tree, h("div", { class: "message error" }, errorText(error)));
      await this.refreshBuses();
      this.resolveProjects();
      return;
    }
    this.resolveProjects();
    this.projectsKnown = true;
    this.renderTree();
    await this.refreshBuses();
    this.live.watchAxes(this.projectList.flatMap((project) => project.axes));
    this.renderTree();
  }

  projectsLoaded(): Project[] {
    return this.projectList;
  }

  /** Update one project in the tree from an API answer, so the tree never lags behind a change. */
  updateProject(project: Project): void {
    const index = this.projectList.findIndex((p) => p.name === project.name);
    if (index >= 0) this.projectList[index] = project;
    else this.projectList.push(project);
    void this.refreshBuses().then(() => this.live.watchAxes(this.projectList.flatMap((p) => p.axes)));
    this.renderTree();
  }

  private renderTree(): void {
    const route = this.location.route;
    const current = route.page === "axis" || route.page === "project" || route.page === "compare" ? route.project : null;
    const currentAxis = route.page === "axis" ? route.axis : null;
    const items: Node[] = [
      h("div", { class: "side-title" }, "Projects", h("a", { href: "/", title: "Create or open a project" }, "Manage")),
    ];
    if (this.projectList.length === 0) items.push(h("div", { class: "empty" }, "No projects yet"));
    for (const project of this.projectList) {
      items.push(
        h("a", { href: buildPath({ page: "project", project: project.name }), class: current === project.name && !currentAxis ? "active" : "", "data-testid": `tree-project-${project.name}` },
          h("span", null, "▾"), h("strong", null, project.name)),
      );
      for (const axis of project.axes) {
        const status = this.live.axis(axis.bus, axis.node_id);
        const state = axisStateText(status);
        const view = route.page === "axis" ? route.view : "dashboard";
        items.push(
          h("a", {
            href: buildPath({ page: "axis", project: project.name, axis: axis.name, view }),
            class: `axis ${current === project.name && currentAxis === axis.name ? "active" : ""}`,
            "data-testid": `tree-axis-${axis.name}`,
            title: `${axis.device}, node ${axis.node_id} on bus ${axis.bus}: ${state.text}`,
          },
            h("span", { class: `dot ${state.tone}` }),
            h("span", null, axis.name),
            h("span", { class: `state ${state.tone}`, "data-testid": `tree-state-${axis.name}` }, state.text)),
        );
      }
    }
    items.push(h("div", { class: "side-title" }, "Tools"));
    const tools: [Route, string][] = [
      [{ page: "bus" }, "Bus and scan"],
      [{ page: "terminal" }, "Dialog terminal"],
      [{ page: "dictionaries" }, "Object dictionaries"],
      [{ page: "motors" }, "Motor catalog"],
    ];
    for (const [target, label] of tools) {
      items.push(h("a", { href: buildPath(target), class: samePage(target, route) ? "active" : "" }, label));
    }
    replaceChildren(this.tree, ...items);
  }

  // ---- status -------------------------------------------------------------------------------------------------

  private async refreshHealth(): Promise<void> {
    try {
      const health = await getHealth();
      this.setServer("online", `Server online · v${health.version}`);
    } catch (error) {
      this.setServer("offline", `Server offline: ${errorText(error)}`);
    }
  }

  private setServer(state: "connecting" | "online" | "offline", text = "Connecting to server…"): void {
    this.serverStatus.dataset.state = state;
    replaceChildren(this.serverStatus, h("span", { class: "dot" }), text);
  }

  async refreshBuses(): Promise<void> {
    try {
      const buses = await driveApi.buses();
      if (this.projectsKnown) learnBuses(buses, this.projectList.flatMap((project) => project.buses));
      this.live.setBuses(buses.map((bus) => ({ name: bus.id, state: bus.connected ? "connected" : bus.error ? `error: ${bus.error}` : "disconnected" })));
    } catch {
      if (this.projectsKnown) learnBuses([], []);
      this.live.setBuses([]);
    }
  }

  private renderBusStatus(): void {
    const buses = this.live.buses();
    const user = this.live.user();
    replaceChildren(this.userStatus, user ? `${user.name} · ${user.level}` : "local operator");
    if (buses.length === 0) {
      replaceChildren(this.busStatus, h("span", { class: "dot idle" }), "No bus connected");
      return;
    }
    const text = buses.map((bus) => `${bus.name}: ${bus.state}`).join(" · ");
    const tone = buses.every((bus) => bus.state === "connected") ? "ok" : "warn";
    replaceChildren(this.busStatus, h("span", { class: `dot ${tone}` }), text);
  }
}
