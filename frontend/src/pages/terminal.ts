/** Dialog terminal: read or write any object on up to 4 axes, with continuous monitoring (manual §1.8.27). */

import type { Page, PageContext } from "../app";
import { errorText } from "../components/ui";
import { driveApi, serverBus, type ObjectValue } from "../client/drives";
import { h, replaceChildren } from "../lib/dom";
import { TerminalSocket, type WatchRow } from "../client/terminal-socket";

const MAX_AXES = 4;
const MAX_ROWS = 32;
const PERIODS = [100, 200, 500, 1000];
const STORAGE_KEY = "servostudio.terminal";

interface Target {
  label: string;
  bus: string;
  node: number;
}

interface Line {
  target: HTMLSelectElement;
  object: HTMLInputElement;
  value: HTMLElement;
  text: HTMLElement;
  input: HTMLInputElement;
  physical: HTMLInputElement;
  row: HTMLElement;
}

export async function terminalPage(context: PageContext): Promise<Page> {
  const { app } = context;
  await app.projectsReady;
  const targets: Target[] = [];
  for (const project of app.projectsLoaded()) {
    for (const axis of project.axes) targets.push({ label: `${project.name}/${axis.name} (${serverBus(axis.bus)}:${axis.node_id})`, bus: serverBus(axis.bus), node: axis.node_id });
  }
  for (const bus of await driveApi.buses().catch(() => [])) {
    for (const node of bus.nodes) {
      if (!targets.some((t) => t.bus === bus.id && t.node === node.node)) targets.push({ label: `${bus.id}:${node.node}`, bus: bus.id, node: node.node });
    }
  }
  const body = h("tbody");
  const log = h("div", { class: "terminal-log panel-body", "data-testid": "terminal-log" });
  const message = h("div");
  const monitor = h("input", { type: "checkbox", "data-testid": "terminal-monitor" });
  const period = h("select", { "aria-label": "Monitoring period" }, PERIODS.map((ms) => h("option", { value: String(ms) }, `${ms} ms`)));
  period.value = "200";
  const lines: Line[] = [];
  const socket = new TerminalSocket();

  const logLine = (text: string, kind = "") => {
    const time = new Date().toISOString().slice(11, 23);
    log.prepend(h("div", { class: kind }, `${time}  ${text}`));
    while (log.childElementCount > 200) log.lastElementChild?.remove();
  };

  const itemOf = (line: Line) => {
    const target = targets[Number(line.target.value)];
    return target && line.object.value.trim() ? { bus: target.bus, node: target.node, object: line.object.value.trim() } : null;
  };

  const show = (line: Line, value: ObjectValue | undefined, error: string | undefined) => {
    line.value.textContent = error ? "" : value ? String(value.physical) : "";
    line.text.textContent = error ? error : value ? `${value.text}  (${value.label}, raw ${value.raw})` : "";
    line.text.className = error ? "error-text" : "";
  };

  const addLine = (targetIndex = 0, object = "") => {
    if (lines.length >= MAX_ROWS) return;
    const target = h("select", { "aria-label": "Axis", style: { maxWidth: "210px" } }, targets.map((t, i) => h("option", { value: String(i) }, t.label)));
    target.value = String(Math.min(targetIndex, Math.max(0, targets.length - 1)));
    const line: Line = {
      target,
      object: h("input", { type: "text", value: object, style: { width: "130px" }, placeholder: "0x6041 or statusword", "data-testid": "terminal-object", spellcheck: "false" }),
      value: h("span", { class: "mono", "data-testid": "terminal-value" }),
      text: h("span"),
      input: h("input", { type: "text", style: { width: "90px" }, "data-testid": "terminal-input", "aria-label": "Value to write" }),
      physical: h("input", { type: "checkbox", title: "The value is in the object's unit" }),
      row: h("tr"),
    };
    const write = async () => {
      const item = itemOf(line);
      if (!item || !line.input.value.trim()) return;
      const typed = line.input.value.trim();
      const value = /^-?(\d+\.?\d*|\.\d+)(e-?\d+)?$/i.test(typed) ? Number(typed) : typed;
      try {
        const written = await driveApi.writeKey(item.bus, item.node, item.object, value, line.physical.checked);
        show(line, written, undefined);
        logLine(`write ${item.bus}:${item.node} ${written.label} = ${written.text}`);
      } catch (error) {
        logLine(`write ${item.bus}:${item.node} ${item.object} = ${typed}: ${errorText(error)}`, "error-text");
      }
    };
    line.input.addEventListener("keydown", (event) => event.key === "Enter" && void write());
    line.object.addEventListener("change", () => { save(); restartMonitor(); });
    target.addEventListener("change", () => { save(); restartMonitor(); });
    line.row.append(
      h("td", null, target), h("td", null, line.object), h("td", { class: "num" }, line.value), h("td", { class: "wrap" }, line.text),
      h("td", null, h("span", { class: "toolbar", style: { flexWrap: "nowrap" } }, line.input, h("label", { class: "check", title: "physical value (object's unit)" }, line.physical, "unit"),
        h("button", { class: "small", "data-testid": "terminal-write", onclick: () => void write() }, "Write"),
        h("button", { class: "small", title: "Remove this line", onclick: () => { lines.splice(lines.indexOf(line), 1); line.row.remove(); save(); restartMonitor(); } }, "×"))));
    lines.push(line);
    body.append(line.row);
  };

  const items = () => lines.map(itemOf).filter((item): item is { bus: string; node: number; object: string } => item !== null);

  const check = (): boolean => {
    const axes = new Set(items().map((item) => `${item.bus}:${item.node}`));
    if (axes.size > MAX_AXES) {
      replaceChildren(message, h("div", { class: "message error" }, `The terminal works on up to ${MAX_AXES} axes at once; these lines use ${axes.size}.`));
      return false;
    }
    replaceChildren(message);
    return true;
  };

  const readAll = async () => {
    if (!check()) return;
    const byNode = new Map<string, { line: Line; item: { bus: string; node: number; object: string } }[]>();
    for (const line of lines) {
      const item = itemOf(line);
      if (!item) continue;
      const key = `${item.bus}:${item.node}`;
      if (!byNode.has(key)) byNode.set(key, []);
      byNode.get(key)!.push({ line, item });
    }
    await Promise.all([...byNode.values()].map(async (group) => {
      const { bus, node } = group[0].item;
      try {
        const results = await driveApi.readKeys(bus, node, group.map((g) => g.item.object));
        results.forEach((result, i) => {
          show(group[i].line, result.value ?? undefined, result.error ?? undefined);
          logLine(`read ${bus}:${node} ${result.value ? `${result.value.label} = ${result.value.text}` : `${result.object}: ${result.error}`}`, result.error ? "error-text" : "");
        });
      } catch (error) {
        for (const { line } of group) show(line, undefined, errorText(error));
      }
    }));
  };

  const restartMonitor = () => {
    if (!monitor.checked) {
      socket.watch([], Number(period.value));
      return;
    }
    if (!check()) {
      monitor.checked = false;
      return;
    }
    socket.watch(items(), Number(period.value));
  };

  socket.onRows = (rows: WatchRow[]) => {
    for (const line of lines) {
      const item = itemOf(line);
      const row = item && rows.find((r) => r.bus === item.bus && r.node === item.node && r.object === item.object);
      if (row) show(line, row.value, row.error);
    }
  };
  socket.onError = (text) => replaceChildren(message, h("div", { class: "message error" }, text));
  monitor.addEventListener("change", restartMonitor);
  period.addEventListener("change", restartMonitor);

  const save = () => localStorage.setItem(STORAGE_KEY, JSON.stringify(lines.map((line) => ({ target: targets[Number(line.target.value)]?.label, object: line.object.value }))));
  const stored = JSON.parse(localStorage.getItem(STORAGE_KEY) ?? "[]") as { target: string; object: string }[];
  if (stored.length) for (const line of stored) addLine(Math.max(0, targets.findIndex((t) => t.label === line.target)), line.object);
  else for (const object of ["statusword", "0x6061", "0x6064", "0x606C"]) addLine(0, object);

  return {
    title: "Dialog terminal",
    dispose: () => socket.close(),
    focusSearch: () => { lines[0]?.object.focus(); return true; },
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Dialog terminal"), h("span", { class: "muted" }, `up to ${MAX_AXES} axes, ${MAX_ROWS} objects`)),
      targets.length === 0 ? h("div", { class: "message warn" }, "No axis known: add axes to a project or scan a bus first.") : null,
      h("div", { class: "toolbar" },
        h("button", { class: "primary", "data-testid": "terminal-read", onclick: () => void readAll() }, "Read all"),
        h("label", { class: "check" }, monitor, "Monitor continuously"), period,
        h("button", { onclick: () => { addLine(0, ""); save(); } }, "Add line")),
      message,
      h("div", { class: "panel" }, h("table", { class: "data", "data-testid": "terminal-table" },
        h("thead", null, h("tr", null, ["Axis", "Object", "Value", "Text", "Write"].map((t) => h("th", null, t)))), body)),
      h("section", { class: "panel" }, h("h2", null, "Log"), log)),
  };
}
