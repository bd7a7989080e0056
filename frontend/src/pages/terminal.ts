/** Dialog terminal: read or write any object on up to 4 axes, with continuous monitoring (manual §1.8.27). */

import type { App, Page, PageContext } from "../app";
import { driveApi, serverBus, type ObjectValue } from "../client/drives";
import { TerminalSocket, type WatchItem, type WatchRow } from "../client/terminal-socket";
import { errorText, messageView, type Message } from "../components/ui";
import { h, Scope, state, untrack, type State } from "../lib/dom";

const MAX_AXES = 4;
const MAX_ROWS = 32;
const MAX_LOG = 200;
const PERIODS = [100, 200, 500, 1000];
const STORAGE_KEY = "servostudio.terminal";
const DEFAULT_OBJECTS = ["statusword", "0x6061", "0x6064", "0x606C"];

interface Target {
  label: string;
  bus: string;
  node: number;
}

/** One line of the terminal: which object of which axis, what was last read or written, what to write. */
export interface Line {
  target: State<number>;
  object: State<string>;
  input: State<string>;
  physical: State<boolean>;
  shown: State<{ value?: ObjectValue; error?: string }>;
}

interface LogEntry {
  text: string;
  kind: string;
}

interface TerminalView {
  targets: Target[];
  lines: State<Line[]>;
  monitor: State<boolean>;
  period: State<number>;
  message: State<Message | null>;
  log: State<LogEntry[]>;
  socket: TerminalSocket;
  /** Each line's row, built once in the page's scope (adding or removing a line leaves the others alone). */
  rows: WeakMap<Line, HTMLElement>;
  scope: Scope;
}

export async function terminalPage(context: PageContext): Promise<Page> {
  const targets = await knownTargets(context.app);
  const scope = new Scope();
  const view: TerminalView = {
    targets, lines: state(storedLines(targets)), monitor: state(false), period: state(200), message: state<Message | null>(null),
    log: state<LogEntry[]>([]), socket: new TerminalSocket(), rows: new WeakMap(), scope,
  };
  view.socket.onRows = (rows) => showRows(view, rows);
  view.socket.onError = (text) => (view.message.val = { text, tone: "error" });
  let first = true;
  scope.effect(() => {
    const lines = linesToStore(view);
    if (!first) localStorage.setItem(STORAGE_KEY, JSON.stringify(lines));
    first = false;
  });
  followMonitor(view, scope);
  return {
    title: "Dialog terminal",
    dispose: () => {
      scope.dispose();
      view.socket.close();
    },
    focusSearch: () => {
      view.rows.get(view.lines.rawVal[0])?.querySelector<HTMLInputElement>("[data-testid=terminal-object]")?.focus();
      return true;
    },
    element: scope.run(() => h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Dialog terminal"), h("span", { class: "muted" }, `up to ${MAX_AXES} axes, ${MAX_ROWS} objects`)),
      targets.length === 0 ? h("div", { class: "message warn" }, "No axis known: add axes to a project or scan a bus first.") : null,
      terminalToolbar(view),
      messageView(view.message),
      h("div", { class: "panel" }, h("table", { class: "data", "data-testid": "terminal-table" },
        h("thead", null, h("tr", null, ["Axis", "Object", "Value", "Text", "Write"].map((t) => h("th", null, t)))),
        h("tbody", null, () => view.lines.val.map((line) => rowOf(view, line))))),
      h("section", { class: "panel" }, h("h2", null, "Log"),
        h("div", { class: "terminal-log panel-body", "data-testid": "terminal-log" },
          () => view.log.val.map((entry) => h("div", { class: entry.kind }, entry.text)))))),
  };
}

/** The axes of the projects (by their server bus), then the other nodes the server knows. */
async function knownTargets(app: App): Promise<Target[]> {
  await app.projectsReady;
  const targets: Target[] = [];
  for (const project of app.projectsLoaded()) {
    for (const axis of project.axes) targets.push({ label: `${project.name}/${axis.name} (${serverBus(axis.bus)}:${axis.node_id})`, bus: serverBus(axis.bus), node: axis.node_id });
  }
  for (const bus of await driveApi.buses().catch(() => [])) {
    for (const node of bus.nodes ?? []) {
      if (!targets.some((t) => t.bus === bus.id && t.node === node.node)) targets.push({ label: `${bus.id}:${node.node}`, bus: bus.id, node: node.node });
    }
  }
  return targets;
}

export function newLine(target: number, object: string): Line {
  return { target: state(target), object: state(object), input: state(""), physical: state(false), shown: state({}) };
}

/** The lines remembered in this browser (by target label), else four useful objects of the first axis. */
function storedLines(targets: Target[]): Line[] {
  const stored = JSON.parse(localStorage.getItem(STORAGE_KEY) ?? "[]") as { target: string; object: string }[];
  const clamp = (index: number) => Math.min(index, Math.max(0, targets.length - 1));
  if (stored.length === 0) return DEFAULT_OBJECTS.map((object) => newLine(0, object));
  return stored.slice(0, MAX_ROWS).map((line) => newLine(clamp(Math.max(0, targets.findIndex((t) => t.label === line.target))), line.object));
}

/** What the browser remembers of the lines (read in a binding: saved again whenever a line changes). */
function linesToStore(view: TerminalView): { target: string | undefined; object: string }[] {
  return view.lines.val.map((line) => ({ target: view.targets[line.target.val]?.label, object: line.object.val }));
}

/** The object a line names on its axis (null while it names none). */
export function itemOf(targets: Target[], line: Line): WatchItem | null {
  const target = targets[line.target.val];
  const object = line.object.val.trim();
  return target && object ? { bus: target.bus, node: target.node, object } : null;
}

const items = (view: TerminalView) => view.lines.val.map((line) => itemOf(view.targets, line)).filter((item) => item !== null);

/** The refusal when the lines use more axes than the terminal may work on at once, else null. */
export function axesRefusal(lineItems: WatchItem[]): string | null {
  const axes = new Set(lineItems.map((item) => `${item.bus}:${item.node}`));
  return axes.size > MAX_AXES ? `The terminal works on up to ${MAX_AXES} axes at once; these lines use ${axes.size}.` : null;
}

/** Watch the lines' objects while "Monitor continuously" is on (again whenever a line or the period changes). */
function followMonitor(view: TerminalView, scope: Scope): void {
  let watching = false;
  scope.effect(() => {
    const on = view.monitor.val;
    const period = view.period.val;
    const watched = items(view);
    if (!on) {
      if (watching) view.socket.watch([], period);
      watching = false;
      return;
    }
    const refusal = axesRefusal(watched);
    view.message.val = refusal ? { text: refusal, tone: "error" } : null;
    if (refusal) {
      queueMicrotask(() => (view.monitor.val = false));
      return;
    }
    view.socket.watch(watched, period);
    watching = true;
  });
}

function showRows(view: TerminalView, rows: WatchRow[]): void {
  for (const line of view.lines.rawVal) {
    const item = itemOf(view.targets, line);
    const row = item && rows.find((r) => r.bus === item.bus && r.node === item.node && r.object === item.object);
    if (row) line.shown.val = { value: row.value, error: row.error };
  }
}

function logLine(view: TerminalView, text: string, kind = ""): void {
  const time = new Date().toISOString().slice(11, 23);
  view.log.val = [{ text: `${time}  ${text}`, kind }, ...view.log.rawVal].slice(0, MAX_LOG);
}

function terminalToolbar(view: TerminalView): HTMLElement {
  const period = h("select", { "aria-label": "Monitoring period", onchange: (event: Event) => (view.period.val = Number((event.target as HTMLSelectElement).value)) },
    PERIODS.map((ms) => h("option", { value: String(ms) }, `${ms} ms`)));
  period.value = String(view.period.rawVal);
  const addLine = () => {
    if (view.lines.rawVal.length < MAX_ROWS) view.lines.val = [...view.lines.rawVal, newLine(0, "")];
  };
  return h("div", { class: "toolbar" },
    h("button", { class: "primary", "data-testid": "terminal-read", onclick: () => void readAll(view) }, "Read all"),
    h("label", { class: "check" }, h("input", {
      type: "checkbox", "data-testid": "terminal-monitor", checked: view.monitor,
      onchange: (event: Event) => (view.monitor.val = (event.target as HTMLInputElement).checked),
    }), "Monitor continuously"),
    period,
    h("button", { onclick: addLine }, "Add line"));
}

/** Read every line once, one batch per node. */
async function readAll(view: TerminalView): Promise<void> {
  const refusal = axesRefusal(items(view));
  view.message.val = refusal ? { text: refusal, tone: "error" } : null;
  if (refusal) return;
  const byNode = new Map<string, { line: Line; item: WatchItem }[]>();
  for (const line of view.lines.rawVal) {
    const item = itemOf(view.targets, line);
    if (!item) continue;
    const key = `${item.bus}:${item.node}`;
    byNode.set(key, [...(byNode.get(key) ?? []), { line, item }]);
  }
  await Promise.all([...byNode.values()].map(async (group) => {
    const { bus, node } = group[0].item;
    try {
      const results = await driveApi.readKeys(bus, node, group.map((g) => g.item.object));
      results.forEach((result, i) => {
        group[i].line.shown.val = { value: result.value ?? undefined, error: result.error ?? undefined };
        logLine(view, `read ${bus}:${node} ${result.value ? `${result.value.label} = ${result.value.text}` : `${result.object}: ${result.error}`}`, result.error ? "error-text" : "");
      });
    } catch (error) {
      for (const { line } of group) line.shown.val = { error: errorText(error) };
    }
  }));
}

/** Write the line's typed value: a number when it reads as one, else the text (an enumeration label, hex). */
async function writeLine(view: TerminalView, line: Line): Promise<void> {
  const item = itemOf(view.targets, line);
  const typed = line.input.rawVal.trim();
  if (!item || !typed) return;
  const value = /^-?(\d+\.?\d*|\.\d+)(e-?\d+)?$/i.test(typed) ? Number(typed) : typed;
  try {
    const written = await driveApi.writeKey(item.bus, item.node, item.object, value, line.physical.rawVal);
    line.shown.val = { value: written };
    logLine(view, `write ${item.bus}:${item.node} ${written.label} = ${written.text}`);
  } catch (error) {
    logLine(view, `write ${item.bus}:${item.node} ${item.object} = ${typed}: ${errorText(error)}`, "error-text");
  }
}

function rowOf(view: TerminalView, line: Line): HTMLElement {
  let row = view.rows.get(line);
  // Built in the page's scope, not in the list's content (whose bindings stop each time the list changes).
  if (!row) view.rows.set(line, (row = untrack(() => view.scope.run(() => lineRow(view, line)))));
  return row;
}

const inputText = (event: Event) => (event.target as HTMLInputElement).value;

function lineRow(view: TerminalView, line: Line): HTMLElement {
  const target = h("select", { "aria-label": "Axis", style: { maxWidth: "210px" }, onchange: (event: Event) => (line.target.val = Number(inputText(event))) },
    view.targets.map((t, i) => h("option", { value: String(i) }, t.label)));
  target.value = String(line.target.rawVal);
  const object = h("input", { type: "text", value: line.object.rawVal, style: { width: "130px" }, placeholder: "0x6041 or statusword",
    "data-testid": "terminal-object", spellcheck: "false", onchange: (event: Event) => (line.object.val = inputText(event)) });
  const write = () => {
    line.object.val = object.value;
    void writeLine(view, line);
  };
  const input = h("input", { type: "text", value: line.input, style: { width: "90px" }, "data-testid": "terminal-input", "aria-label": "Value to write",
    oninput: (event: Event) => (line.input.val = inputText(event)), onkeydown: (event: KeyboardEvent) => event.key === "Enter" && write() });
  const remove = () => (view.lines.val = view.lines.rawVal.filter((candidate) => candidate !== line));
  return h("tr", null,
    h("td", null, target), h("td", null, object),
    h("td", { class: "num" }, h("span", { class: "mono", "data-testid": "terminal-value" }, () => shownValue(line))),
    h("td", { class: "wrap" }, h("span", { class: () => (line.shown.val.error ? "error-text" : "") }, () => shownText(line))),
    h("td", null, h("span", { class: "toolbar", style: { flexWrap: "nowrap" } }, input,
      h("label", { class: "check", title: "physical value (object's unit)" }, h("input", {
        type: "checkbox", title: "The value is in the object's unit", checked: line.physical,
        onchange: (event: Event) => (line.physical.val = (event.target as HTMLInputElement).checked),
      }), "unit"),
      h("button", { class: "small", "data-testid": "terminal-write", onclick: write }, "Write"),
      h("button", { class: "small", title: "Remove this line", onclick: remove }, "×"))));
}

function shownValue(line: Line): string {
  const { value, error } = line.shown.val;
  return error || !value ? "" : String(value.physical);
}

function shownText(line: Line): string {
  const { value, error } = line.shown.val;
  if (error) return error;
  return value ? `${value.text}  (${value.label}, raw ${value.raw})` : "";
}
