/**
 * The application: the shell (top bar, project tree, main area), client-side navigation with the History API and
 * the data the shell shows (projects, server and bus state) as reactive states the shell's components bind to.
 * Pages are plain modules that build their element from a `PageContext` (`pages/index.ts`).
 */

import { ApiError, getHealth, getMe, onUnauthenticated, projects, type Project, type UserInfo } from "./client/api";
import { driveApi, learnBuses } from "./client/drives";
import { LiveHub } from "./client/live";
import { projectTree } from "./components/shell/tree";
import { topBar, type ServerState } from "./components/shell/topbar";
import { applyTheme, storedTheme } from "./components/theme";
import { errorText } from "./components/ui";
import { h, replaceChildren, state, type Child, type State } from "./lib/dom";
import { buildPath, parsePath, samePage, type Location, type Route } from "./lib/router";
import { mountPage } from "./pages";
import { installShortcuts } from "./shortcuts";

/** Tree states come from events (`drive_state`, NMT, EMCY); only while the event socket is down are they polled. */
const TREE_FALLBACK_MS = 10000;
const HEALTH_MS = 10000;
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
  /** Run a shortcut of the page itself (the scope's arm, force, stop); false when the page has none. */
  shortcut?(action: string): boolean;
}

export interface PageContext {
  app: App;
  location: Location;
}

export class App {
  readonly live = new LiveHub();
  /** Where the browser is (route and query); the tree and the shortcuts follow it. */
  readonly here: State<Location> = state(parsePath(window.location.pathname, window.location.search));
  /** The projects shown in the tree, each with its axes. */
  readonly projects: State<Project[]> = state([]);
  /** Why the project list could not be loaded (shown in the tree instead of it). */
  readonly projectsError: State<string | null> = state(null);
  readonly server: State<ServerState> = state<ServerState>({ state: "connecting", text: "Connecting to server…" });
  /** Resolves once the project list was loaded (pages that offer axes wait for it). */
  readonly projectsReady: Promise<void>;
  private resolveProjects: () => void = () => undefined;
  private projectsKnown = false;
  /** Counts the changes `updateProject` made, so a list fetched across one is fetched again. */
  private projectChanges = 0;
  private page: Page | null = null;
  private readonly content: State<Child> = state<Child>(null);
  private readonly crumbs: State<Child> = state<Child>(null);
  private mountToken = 0;

  constructor(root: HTMLElement) {
    applyTheme(storedTheme());
    this.projectsReady = new Promise<void>((resolve) => (this.resolveProjects = resolve));
    replaceChildren(root, h("div", { class: "layout" },
      topBar(this, this.crumbs),
      h("aside", { class: "sidebar" }, projectTree(this)),
      h("main", { class: "main" }, () => this.content.val)));
    document.addEventListener("click", (event) => this.onClick(event));
    installShortcuts(this);
    onUnauthenticated(() => this.requireLogin());
    window.addEventListener("popstate", () => this.show(parsePath(window.location.pathname, window.location.search)));
  }

  get location(): Location {
    return this.here.rawVal;
  }

  async start(): Promise<void> {
    void this.refreshHealth();
    void getMe().then((user) => this.live.setUser(user), () => undefined);
    setInterval(() => void this.refreshHealth(), HEALTH_MS);
    this.live.refreshAxis = async (axis) => {
      try {
        const answer = await driveApi.state(axis.bus, axis.node_id);
        this.live.updateAxis(axis.bus, axis.node_id, { online: true, nmt: answer.nmt_state ?? null, statusword: answer.statusword });
      } catch {
        this.live.updateAxis(axis.bus, axis.node_id, { online: false });
      }
    };
    for (const type of ["bus_state", "bus_closed", "scan", "ws_open"] as const) this.live.on(type, () => void this.refreshBuses());
    for (const type of ["emcy", "bootup", "heartbeat_back"] as const) this.live.on(type, () => void this.live.refreshAxes());
    setInterval(() => {
      if (!this.live.connected() && document.visibilityState === "visible") void this.live.refreshAxes();
    }, TREE_FALLBACK_MS);
    this.live.start();
    this.mount();
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
    history.replaceState(null, "", buildPath(this.location.route, query));
    this.here.val = parsePath(window.location.pathname, window.location.search);
  }

  /** Focus the page's search field (shortcut `/`). */
  focusSearch(): boolean {
    return this.page?.focusSearch?.() ?? false;
  }

  /** A shortcut only the current page knows (shortcuts.ts asks after its own). */
  pageShortcut(action: string): boolean {
    return this.page?.shortcut?.(action) ?? false;
  }

  private show(location: Location): void {
    const previous = this.location;
    this.here.val = location;
    if (this.page?.update && samePage(previous.route, location.route) && this.page.update(location)) return;
    this.mount();
  }

  /** Build the page of the current location; a page that is still loading when the user moves on is dropped. */
  private mount(): void {
    this.page?.dispose?.();
    this.page = null;
    const token = ++this.mountToken;
    this.content.val = h("div", { class: "page" }, h("div", { class: "empty-state" }, "Loading…"));
    mountPage({ app: this, location: this.location }).then(
      (page) => {
        if (token !== this.mountToken) return page.dispose?.();
        this.page = page;
        document.title = page.title === APP_NAME ? APP_NAME : `${page.title} · ${APP_NAME}`;
        this.crumbs.val = page.crumbs ?? [page.title];
        this.content.val = page.element;
      },
      (error: unknown) => {
        if (token !== this.mountToken) return;
        document.title = `Error · ${APP_NAME}`;
        this.content.val = h("div", { class: "page" }, h("div", { class: "message error", "data-testid": "page-error" }, errorText(error)));
      },
    );
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

  // ---- logging in ---------------------------------------------------------------------------------------------

  /** Nobody is logged in, or the session ended: the login page, which comes back here afterwards. */
  private requireLogin(): void {
    const page = this.location.route.page;
    if (page === "login" || page === "setup") return;
    this.navigate({ page: "login" }, { next: window.location.pathname + window.location.search }, true);
  }

  /** After a login or the setup: the user in the top bar, what it may now see, and the page it was going to. */
  signedIn(user: UserInfo): void {
    this.live.setUser(user);
    const next = new URL(this.location.query.next ?? "/", window.location.origin);
    const target = next.origin === window.location.origin ? next : new URL("/", window.location.origin);
    history.replaceState(null, "", target.pathname + target.search);
    this.show(parsePath(target.pathname, target.search));
    void this.refreshProjects();
  }

  // ---- projects and buses -------------------------------------------------------------------------------------

  /** Reload the projects shown in the tree (after create, rename, add axis…). */
  async refreshProjects(): Promise<void> {
    try {
      this.projects.val = await this.fetchProjects();
      this.projectsError.val = null;
    } catch (error) {
      this.projects.val = [];
      this.projectsError.val = error instanceof ApiError && error.status === 401 ? "Log in to see the projects." : errorText(error);
    }
    this.projectsKnown = true;
    this.resolveProjects();
    await this.refreshBuses();
    if (this.projectsError.rawVal === null) this.live.watchAxes(this.projects.rawVal.flatMap((project) => project.axes));
  }

  /** Every project, whole; fetched again when a change was made meanwhile: a project created while the page's first
   * list was on its way (a slow server) must not vanish from the tree when that list arrives. */
  private async fetchProjects(): Promise<Project[]> {
    for (;;) {
      const changes = this.projectChanges;
      const summaries = await projects.list();
      const list = await Promise.all(summaries.map((summary) => projects.get(summary.name)));
      if (changes === this.projectChanges) return list;
    }
  }

  projectsLoaded(): Project[] {
    return this.projects.rawVal;
  }

  /** Update one project in the tree from an API answer, so the tree never lags behind a change. */
  updateProject(project: Project): void {
    this.projectChanges += 1;
    const list = this.projects.rawVal;
    const known = list.some((p) => p.name === project.name);
    this.projects.val = known ? list.map((p) => (p.name === project.name ? project : p)) : [...list, project];
    void this.refreshBuses().then(() => this.live.watchAxes(this.projects.rawVal.flatMap((p) => p.axes)));
  }

  async refreshBuses(): Promise<void> {
    try {
      const buses = await driveApi.buses();
      if (this.projectsKnown) learnBuses(buses, this.projects.rawVal.flatMap((project) => project.buses));
      this.live.setBuses(buses.map((bus) => ({ name: bus.id, state: bus.connected ? "connected" : bus.error ? `error: ${bus.error}` : "disconnected" })));
    } catch {
      if (this.projectsKnown) learnBuses([], []);
      this.live.setBuses([]);
    }
  }

  private async refreshHealth(): Promise<void> {
    try {
      const health = await getHealth();
      this.server.val = { state: "online", text: `Server online · v${health.version}` };
    } catch (error) {
      this.server.val = { state: "offline", text: `Server offline: ${errorText(error)}` };
    }
  }
}
