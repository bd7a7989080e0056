/**
 * Axis dashboard: CiA 402 state with the allowed transitions, mode of operation, status word bit by bit, faults and
 * warnings with the manual's remedy, live measurements and digital I/O. Live values come from the server's
 * terminal socket (it samples; this page renders), faults are fetched when the status word's fault or warning
 * bit changes.
 */

import { projectAddress } from "../client/api";
import { errorText, toast } from "../components/ui";
import { driveApi, serverBus, type FaultReport, type ObjectValue } from "../client/drives";
import { fieldLabel, extractBits } from "../lib/bits";
import {
  COMMAND_LABELS,
  STATE_LABELS,
  allowedTransitions,
  decodeState,
  type Command,
  type DriveState,
} from "../lib/cia402";
import { h, replaceChildren } from "../lib/dom";
import { enumOptions, type Entry } from "../lib/od";
import { PROFILE_VELOCITY_MODE, dashboardSignals } from "../lib/dashboard-objects";
import { editText, formatValue, parseValue } from "../lib/values";
import { TerminalSocket, type WatchRow } from "../client/terminal-socket";
import type { AxisContext, AxisViewPage } from "./axis";

const LIVE_PERIOD_MS = 200;
const STATE_ORDER: DriveState[] = [
  "not_ready_to_switch_on", "switch_on_disabled", "ready_to_switch_on", "switched_on", "operation_enabled",
  "quick_stop_active", "fault_reaction_active", "fault",
];
/** Target state of each command for the server's state walk (PUT …/state). */
const COMMAND_TARGETS: Record<Exclude<Command, "fault_reset">, string> = {
  shutdown: "ready-to-switch-on",
  switch_on: "switched-on",
  enable_operation: "operation-enabled",
  disable_operation: "switched-on",
  disable_voltage: "switch-on-disabled",
  quick_stop: "quick-stop-active",
};
const NMT_COMMANDS: [string, string][] = [
  ["start", "Start"],
  ["pre-operational", "Pre-operational"],
  ["stop", "Stop"],
  ["reset-node", "Reset node"],
];

export async function dashboardView(context: AxisContext): Promise<AxisViewPage> {
  const { axis, dictionary, page } = context;
  const live = page.app.live;
  const signals = dashboardSignals(dictionary);
  const bus = axis.bus;
  const node = axis.node_id;
  const key = (entry: Entry) => projectAddress(entry.object.index, entry.variable.subindex);

  const stateName = h("span", { class: "state-name idle", "data-testid": "dashboard-state" }, "—");
  const statusHex = h("span", { class: "mono muted", "data-testid": "dashboard-statusword" });
  const nmtText = h("span", { class: "pill", "data-testid": "dashboard-nmt" });
  const stateChips = h("div", { class: "io-row" });
  const transitions = h("div", { class: "toolbar", "data-testid": "dashboard-transitions" });
  const modeText = h("span", { class: "mono", "data-testid": "dashboard-mode" });
  const modeSelect = h("select", { "data-testid": "dashboard-mode-select", "aria-label": "Mode of operation" },
    signals.mode ? enumOptions(signals.mode.variable).map((option) => h("option", { value: String(option.value) }, `${option.text} (${option.value})`)) : []);
  const swBits = h("div", { class: "sw-bits", "data-testid": "dashboard-sw-bits" });
  const readouts = h("div", { class: "readouts", "data-testid": "dashboard-readouts" });
  const faultsBody = h("div", { "data-testid": "dashboard-faults" });
  const ioBody = h("div", { class: "panel-body" });
  const message = h("div");
  const connection = h("span", { class: "right muted" });

  let statusword: number | null = null;
  let modeTouched = false;
  let answered = false;
  modeSelect.addEventListener("change", () => (modeTouched = true));
  let busy = false;
  let faultKey = "";
  const values = new Map<string, ObjectValue>();
  const errors = new Map<string, string>();

  const readoutCells = new Map<string, HTMLElement>();
  for (const entry of signals.measurements) {
    const value = h("span", { class: "value" }, "");
    readoutCells.set(key(entry), value);
    readouts.append(h("div", { class: "readout", title: `${key(entry)} ${entry.variable.description}`, "data-testid": `readout-${key(entry)}` },
      h("div", { class: "label" }, entry.variable.name === "Highest sub-index supported" ? entry.object.name : entry.variable.name),
      h("div", null, value, h("span", { class: "unit" }, entry.variable.unit))));
  }

  const guard = async (label: string, work: () => Promise<void>) => {
    busy = true;
    renderTransitions();
    replaceChildren(message);
    try {
      await work();
    } catch (error) {
      replaceChildren(message, h("div", { class: "message error", "data-testid": "dashboard-error" }, `${label}: ${errorText(error)}`));
    } finally {
      busy = false;
      renderTransitions();
    }
  };

  const runCommand = (command: Command) => guard(COMMAND_LABELS[command], async () => {
    if (command === "fault_reset") {
      showFaults(await driveApi.resetFaults(bus, node));
      const state = await driveApi.state(bus, node);
      applyStatusword(state.statusword);
      return;
    }
    const state = await driveApi.setState(bus, node, COMMAND_TARGETS[command]);
    applyStatusword(state.statusword);
  });

  const renderTransitions = () => {
    const state = statusword === null ? null : decodeState(statusword);
    const online = !answered || (live.axis(bus, node)?.online ?? false);
    replaceChildren(stateChips, STATE_ORDER.map((candidate) => h("span", { class: `led ${candidate === state ? "on" : ""}`, title: STATE_LABELS[candidate] }, stateAbbreviation(candidate))));
    if (!state) {
      replaceChildren(transitions, h("span", { class: "muted" }, online ? "Reading the state…" : "The drive does not answer: connect its bus on the Bus page."));
      return;
    }
    const allowed = allowedTransitions(state);
    replaceChildren(transitions, allowed.length === 0
      ? h("span", { class: "muted" }, "No transition can be commanded in this state.")
      : allowed.map((transition) => h("button", {
        class: transition.command === "enable_operation" ? "primary" : transition.command === "quick_stop" || transition.command === "disable_voltage" ? "danger" : "",
        disabled: busy, "data-testid": `transition-${transition.command}`,
        title: `Transition ${transition.number}: ${STATE_LABELS[state]} → ${STATE_LABELS[transition.target]}`,
        onclick: () => void runCommand(transition.command),
      }, COMMAND_LABELS[transition.command])));
  };

  const applyStatusword = (word: number) => {
    const changedFaultBits = statusword === null || (statusword & 0x88) !== (word & 0x88);
    statusword = word;
    const state = decodeState(word);
    stateName.textContent = STATE_LABELS[state];
    stateName.className = `state-name ${state === "operation_enabled" ? "ok" : state === "fault" || state === "fault_reaction_active" ? "bad" : ""}`;
    statusHex.textContent = `0x${word.toString(16).toUpperCase().padStart(4, "0")}`;
    live.updateAxis(bus, node, { online: true, statusword: word });
    renderTransitions();
    renderStatusBits();
    if (changedFaultBits) void refreshFaults();
  };

  const renderStatusBits = () => {
    const entry = signals.statusword;
    if (!entry || statusword === null) return;
    replaceChildren(swBits, entry.variable.bits.map((field) => {
      const value = extractBits(statusword!, field.first, field.last);
      return [h("div", { class: `bitno ${value ? "set" : ""}` }, fieldLabel(field)), h("div", { class: value ? "set" : "muted", title: field.name }, `${value ? "● " : "○ "}${field.name}`)];
    }));
  };

  const showFaults = (report: FaultReport) => {
    const items: Node[] = [];
    for (const fault of report.faults) items.push(faultItem("fault", fault.code, fault.cia402_code, fault.name, fault.remedy));
    if (report.fault && report.faults.length === 0) {
      items.push(faultItem("fault", null, report.error_code, report.error_text || "Fault", ""));
    }
    for (const warning of report.warnings) items.push(faultItem("warning", warning.code, warning.cia402_code, warning.name, warning.remedy));
    replaceChildren(faultsBody, items.length ? items : h("div", { class: "muted", "data-testid": "no-faults" }, "No fault, no warning."));
    const firstFault = report.faults[0]?.name ?? (report.fault ? report.error_text : "");
    live.updateAxis(bus, node, { faultText: firstFault });
  };

  const refreshFaults = async () => {
    try {
      const report = await driveApi.faults(bus, node);
      const signature = JSON.stringify([report.faults, report.warnings, report.error_code]);
      if (signature !== faultKey) {
        faultKey = signature;
        showFaults(report);
      }
    } catch (error) {
      replaceChildren(faultsBody, h("div", { class: "error-text" }, errorText(error)));
    }
  };

  const renderIo = () => {
    const groups: Node[] = [];
    for (const [title, entry] of [["Inputs", signals.inputs], ["Outputs", signals.outputs]] as const) {
      if (!entry) continue;
      const value = values.get(key(entry));
      const word = typeof value?.raw === "number" ? value.raw : null;
      groups.push(h("div", { style: { marginBottom: "8px" } },
        h("div", { class: "muted", style: { marginBottom: "4px" } }, `${title} · ${key(entry)}`, word === null ? "" : ` = 0x${word.toString(16).toUpperCase().padStart(8, "0")}`),
        h("div", { class: "io-row", "data-testid": `io-${title.toLowerCase()}` }, entry.variable.bits.map((field) => {
          const on = word !== null && extractBits(word, field.first, field.last) !== 0;
          return h("span", { class: `led ${on ? "on" : ""}`, title: `bit ${fieldLabel(field)}: ${field.name}` }, shortName(field.name));
        }))));
    }
    replaceChildren(ioBody, groups.length ? groups : h("div", { class: "muted" }, "This dictionary has no digital I/O objects."));
  };

  const onRows = (rows: WatchRow[]) => {
    for (const row of rows) {
      if (row.value) {
        values.set(row.object, row.value);
        errors.delete(row.object);
      } else if (row.error) {
        errors.set(row.object, row.error);
      }
    }
    const sw = signals.statusword ? values.get(key(signals.statusword)) : undefined;
    if (sw && typeof sw.raw === "number" && sw.raw !== statusword) applyStatusword(sw.raw);
    if (signals.statusword && errors.has(key(signals.statusword)) && !values.has(key(signals.statusword))) {
      live.updateAxis(bus, node, { online: false });
      renderTransitions();
    }
    for (const entry of signals.measurements) {
      const cell = readoutCells.get(key(entry))!;
      const value = values.get(key(entry));
      const error = errors.get(key(entry));
      cell.textContent = error ? "error" : value ? formatValue(entry.variable, value.raw) : "";
      cell.title = error ?? "";
    }
    if (signals.modeDisplay) {
      const mode = values.get(key(signals.modeDisplay));
      modeText.textContent = mode ? formatValue(signals.modeDisplay.variable, mode.raw) : "";
      if (mode && !modeTouched && typeof mode.raw === "number") {
        if (![...modeSelect.options].some((o) => o.value === String(mode.raw))) {
          modeSelect.prepend(h("option", { value: String(mode.raw) }, `${mode.raw} (no mode)`));
        }
        modeSelect.value = String(mode.raw);
      }
    }
    renderIo();
  };

  const terminal = new TerminalSocket();
  terminal.onRows = onRows;
  terminal.onError = (text) => replaceChildren(message, h("div", { class: "message error" }, text));
  terminal.onConnection = (open) => (connection.textContent = open ? `live · every ${LIVE_PERIOD_MS} ms` : "live data reconnecting…");
  const watchedEntries = [signals.statusword, signals.modeDisplay, ...signals.measurements, signals.inputs, signals.outputs]
    .filter((entry): entry is Entry => entry !== null)
    .slice(0, 32);

  // The state comes from REST first (the page shows at once and fills in); the live watch starts after it, when the
  // server knows the node's device (it scans when it must).
  const firstState = async () => {
    try {
      const state = await driveApi.state(bus, node);
      live.updateAxis(bus, node, { online: true, nmt: state.nmt_state });
      nmtText.textContent = `NMT ${state.nmt_state ?? "unknown"}`;
      applyStatusword(state.statusword);
    } catch (error) {
      live.updateAxis(bus, node, { online: false });
      nmtText.textContent = "NMT —";
      const projectBus = context.project.buses.find((b) => b.name === bus);
      replaceChildren(message, h("div", { class: "message warn toolbar", "data-testid": "dashboard-offline" },
        `Drive not reachable: ${errorText(error)}`,
        projectBus ? h("button", {
          class: "small primary", onclick: () => void guard(`Open bus ${projectBus.name}`, async () => {
            await driveApi.openBus(projectBus.interface, projectBus.name);
            await page.app.refreshBuses();
            page.app.navigate({ page: "axis", project: context.project.name, axis: axis.name, view: "dashboard" }, {}, true);
          }),
        }, `Open bus ${projectBus.name} (${projectBus.interface})`) : null));
      renderTransitions();
    }
    answered = true;
    renderTransitions();
    // Built now: the server's id of the project's bus is known once the first drive call has answered.
    terminal.watch(watchedEntries.map((entry) => ({ bus: serverBus(bus), node, object: key(entry) })), LIVE_PERIOD_MS);
  };
  renderTransitions();
  renderIo();
  void firstState();
  const offNmt = live.on("nmt_state", (event) => {
    if (event.bus === serverBus(bus) && event.node === node) nmtText.textContent = `NMT ${String(event.nmt_state)}`;
  });
  const offEmcy = live.on("emcy", (event) => {
    if (event.bus === serverBus(bus) && event.node === node) void refreshFaults();
  });

  const setMode = () => guard("Mode of operation", async () => {
    if (!signals.mode) return;
    await driveApi.writeKey(bus, node, key(signals.mode), Number(modeSelect.value));
    toast(`Mode of operation set to ${modeSelect.selectedOptions[0]?.text ?? modeSelect.value}`, "ok");
  });

  /** Profile velocity quick test: mode, ramps and target velocity written through the server's checks. */
  const quickTest = (): HTMLElement | null => {
    const target = signals.targetVelocity;
    if (!target || !signals.mode) return null;
    const fields: { entry: Entry; input: HTMLInputElement }[] = [];
    const field = (entry: Entry | null, label: string, testid: string) => {
      if (!entry) return null;
      const input = h("input", { type: "text", style: { width: "110px" }, "data-testid": testid, "aria-label": label, inputmode: "decimal" });
      fields.push({ entry, input });
      void driveApi.read(bus, node, key(entry)).then((value) => (input.value = editText(entry.variable, value.raw))).catch(() => undefined);
      return h("label", { class: "field" }, `${label} [${entry.variable.unit}]`, input);
    };
    const write = (entry: Entry, text: string) => {
      const parsed = parseValue(entry.variable, text);
      if (!parsed.ok) throw new Error(`${entry.variable.name}: ${parsed.error}`);
      return driveApi.writeKey(bus, node, key(entry), parsed.raw);
    };
    const run = () => guard("Quick test", async () => {
      await driveApi.writeKey(bus, node, key(signals.mode!), PROFILE_VELOCITY_MODE);
      for (const { entry, input } of fields) await write(entry, input.value);
      toast(`Profile velocity: target ${fields.find((f) => f.entry === target)?.input.value} ${target.variable.unit}`, "ok");
    });
    const stop = () => guard("Quick test", async () => {
      await driveApi.writeKey(bus, node, key(target), 0);
      const own = fields.find((f) => f.entry === target);
      if (own) own.input.value = "0";
    });
    return h("section", { class: "panel" },
      h("h2", null, "Quick test · profile velocity"),
      h("div", { class: "panel-body grid", style: { gap: "8px" } },
        h("div", { class: "toolbar" }, field(signals.acceleration, "Acceleration", "qt-acceleration"), field(signals.deceleration, "Deceleration", "qt-deceleration"),
          field(target, "Target velocity", "qt-velocity")),
        h("div", { class: "toolbar" },
          h("button", { class: "primary", "data-testid": "qt-run", onclick: () => void run() }, "Set mode and run"),
          h("button", { "data-testid": "qt-stop", onclick: () => void stop() }, "Stop (target 0)"),
          h("span", { class: "muted" }, "Runs only while the drive is in Operation enabled."))));
  };

  const element = h("div", { class: "page" },
    message,
    h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1.35fr) minmax(0, 1fr)" } },
      h("section", { class: "panel" },
        h("h2", null, "Device control (CiA 402)", connection),
        h("div", { class: "state-banner" }, stateName, statusHex, nmtText),
        h("div", { class: "panel-body", style: { paddingTop: "0" } },
          stateChips,
          h("div", { style: { margin: "10px 0 6px" }, class: "muted" }, "Allowed transitions"),
          transitions,
          h("div", { style: { margin: "12px 0 6px" }, class: "muted" }, "Mode of operation"),
          h("div", { class: "toolbar" }, h("span", null, "Active: "), modeText,
            signals.mode ? [modeSelect, h("button", { "data-testid": "dashboard-set-mode", onclick: () => void setMode() }, "Set mode")] : null),
          h("div", { style: { margin: "12px 0 6px" }, class: "muted" }, "NMT"),
          h("div", { class: "toolbar" }, NMT_COMMANDS.map(([command, label]) => h("button", {
            class: "small", onclick: () => void guard(`NMT ${label}`, () => driveApi.nmt(bus, command, node)),
          }, label))))),
      h("div", { class: "grid", style: { alignContent: "start" } },
        h("section", { class: "panel" },
          h("h2", null, "Faults and warnings",
            h("span", { class: "right" }, h("button", { class: "small", "data-testid": "fault-reset", onclick: () => void runCommand("fault_reset") }, "Fault reset"))),
          h("div", { class: "panel-body", style: { maxHeight: "160px", overflowY: "auto" } }, faultsBody)),
        quickTest())),
    h("section", { class: "panel" }, h("h2", null, "Measurements"), readouts),
    h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1fr) minmax(0, 1fr)" } },
      h("section", { class: "panel" }, h("h2", null, "Status word", h("span", { class: "right mono" }, signals.statusword ? key(signals.statusword) : "")),
        h("div", { class: "panel-body" }, swBits)),
      h("section", { class: "panel" }, h("h2", null, "Digital I/O"), ioBody)));

  return {
    element,
    dispose: () => {
      terminal.close();
      offNmt();
      offEmcy();
    },
  };
}

function faultItem(kind: "fault" | "warning", code: number | null, cia402: number, name: string, remedy: string): HTMLElement {
  return h("div", { class: `fault-item ${kind}`, "data-testid": `${kind}-item` },
    h("div", { class: "title" }, `${kind === "fault" ? "Fault" : "Warning"}${code !== null ? ` ${code}` : ""}: ${name}`,
      h("span", { class: "mono muted" }, `  0x${cia402.toString(16).toUpperCase().padStart(4, "0")}`)),
    remedy ? h("div", null, remedy) : null);
}

function stateAbbreviation(state: DriveState): string {
  return {
    not_ready_to_switch_on: "NRDY", switch_on_disabled: "SOD", ready_to_switch_on: "RTSO", switched_on: "SO",
    operation_enabled: "OE", quick_stop_active: "QS", fault_reaction_active: "FRA", fault: "F",
  }[state];
}

/** A short LED label from a bit name: "IN1", "Negative limit switch" → "LIM−", "Home switch" → "Home". */
function shortName(name: string): string {
  const match = /\b(IN|OUT)\s*(\d+)\b/i.exec(name);
  if (match) return `${match[1].toUpperCase()}${match[2]}`;
  if (/negative limit/i.test(name)) return "LIM−";
  if (/positive limit/i.test(name)) return "LIM+";
  const words = name.split(/[\s/(),]+/).filter(Boolean);
  return words.length ? words[0].slice(0, 8) : name;
}
