/**
 * Device control (CiA 402): the state from the status word with the strip of the eight states, one button per
 * transition the state allows (manual L2952–3042; enabling is always an explicit click), the mode of operation
 * (active mode and a selector over 0x6060's enumeration) and the NMT commands — the last two only where the device
 * has them (a TTA-PRO on PROFIBUS-DP has neither: its state machine is CiA 402's through its PZD words).
 */

import { enumEditor } from "../editors";
import {
  COMMAND_LABELS,
  STATE_LABELS,
  allowedTransitions,
  decodeState,
  type Command,
  type DriveState,
} from "../../lib/cia402";
import { derive, h, untrack, valueOf, type Bindable, type State } from "../../lib/dom";
import type { Entry, Scalar } from "../../lib/od";

export const STATE_ORDER: DriveState[] = [
  "not_ready_to_switch_on", "switch_on_disabled", "ready_to_switch_on", "switched_on", "operation_enabled",
  "quick_stop_active", "fault_reaction_active", "fault",
];
const NMT_COMMANDS: [string, string][] = [
  ["start", "Start"],
  ["pre-operational", "Pre-operational"],
  ["stop", "Stop"],
  ["reset-node", "Reset node"],
];
const ABBREVIATIONS: Record<DriveState, string> = {
  not_ready_to_switch_on: "NRDY", switch_on_disabled: "SOD", ready_to_switch_on: "RTSO", switched_on: "SO",
  operation_enabled: "OE", quick_stop_active: "QS", fault_reaction_active: "FRA", fault: "F",
};

export interface DeviceControlProps {
  /** The status word, null until the drive answered. */
  statusword: State<number | null>;
  /** False once it is known that the drive does not answer. */
  reachable: State<boolean>;
  /** A command is under way: the transition buttons wait. */
  busy: State<boolean>;
  /** This page armed the axis (docs/motion-safety.md): Enable operation waits for it. */
  armed: Bindable<boolean>;
  /** `NMT <state>` */
  nmt: State<string>;
  /** The live data's connection (`live · every 200 ms`, `reconnecting…`). */
  connection: State<string>;
  /** 0x6060 when the dictionary has it, with the active mode (0x6061) as raw value and as text. */
  mode: Entry | null;
  activeMode: Bindable<Scalar>;
  activeModeText: Bindable<string>;
  /** The device has CANopen's NMT (the NMT buttons); a PROFIBUS-DP drive has none. */
  nmtCommands: boolean;
  /** The device has CiA 402 modes of operation (0x6060 or 0x6061). */
  modes: boolean;
  onCommand(command: Command): void;
  onSetMode(raw: number, label: string): void;
  onNmt(command: string, label: string): void;
}

export function deviceControl(props: DeviceControlProps): HTMLElement {
  const driveState = derive(() => (props.statusword.val === null ? null : decodeState(props.statusword.val)));
  const caption = (text: string, top: number) => h("div", { style: { margin: `${top}px 0 6px` }, class: "muted" }, text);
  return h("section", { class: "panel" },
    h("h2", null, "Device control (CiA 402)", h("span", { class: "right muted" }, props.connection)),
    stateBanner(props, driveState),
    h("div", { class: "panel-body", style: { paddingTop: "0" } },
      h("div", { class: "io-row" }, STATE_ORDER.map((candidate) => h("span", {
        class: () => `led ${candidate === driveState.val ? "on" : ""}`, title: STATE_LABELS[candidate],
      }, ABBREVIATIONS[candidate]))),
      caption("Allowed transitions", 10),
      transitionButtons(props, driveState),
      props.modes ? modeRow(props, caption) : null,
      props.nmtCommands ? nmtRow(props, caption) : null));
}

function modeRow(props: DeviceControlProps, caption: (text: string, top: number) => HTMLElement): HTMLElement[] {
  return [
    caption("Mode of operation", 12),
    h("div", { class: "toolbar" }, h("span", null, "Active: "),
      h("span", { class: "mono", "data-testid": "dashboard-mode" }, () => valueOf(props.activeModeText)),
      props.mode ? modeSelector(props.mode, props) : null),
  ];
}

function nmtRow(props: DeviceControlProps, caption: (text: string, top: number) => HTMLElement): HTMLElement[] {
  return [
    caption("NMT", 12),
    h("div", { class: "toolbar", "data-testid": "dashboard-nmt-commands" }, NMT_COMMANDS.map(([command, label]) =>
      h("button", { class: "small", onclick: () => props.onNmt(command, label) }, label))),
  ];
}

function stateBanner(props: DeviceControlProps, driveState: State<DriveState | null>): HTMLElement {
  const tone = (state: DriveState | null) =>
    state === null ? "idle" : state === "operation_enabled" ? "ok" : state === "fault" || state === "fault_reaction_active" ? "bad" : "";
  return h("div", { class: "state-banner" },
    h("span", { class: () => `state-name ${tone(driveState.val)}`, "data-testid": "dashboard-state" },
      () => (driveState.val === null ? "—" : STATE_LABELS[driveState.val])),
    h("span", { class: "mono muted", "data-testid": "dashboard-statusword" },
      () => (props.statusword.val === null ? "" : `0x${props.statusword.val.toString(16).toUpperCase().padStart(4, "0")}`)),
    h("span", { class: "pill", "data-testid": "dashboard-nmt" }, props.nmt));
}

/** The buttons of the transitions the current state allows; rebuilt when the state (not any status bit) changes. */
function transitionButtons(props: DeviceControlProps, driveState: State<DriveState | null>): HTMLElement {
  return h("div", { class: "toolbar", "data-testid": "dashboard-transitions" }, () => {
    const state = driveState.val;
    if (state === null) {
      return h("span", { class: "muted" }, props.reachable.val ? "Reading the state…" : "The drive does not answer: connect its bus on the Bus page.");
    }
    const allowed = allowedTransitions(state);
    if (allowed.length === 0) return h("span", { class: "muted" }, "No transition can be commanded in this state.");
    return untrack(() => allowed.map((transition) => {
      const enabling = transition.command === "enable_operation";
      const title = `Transition ${transition.number}: ${STATE_LABELS[state]} → ${STATE_LABELS[transition.target]}`;
      return h("button", {
        class: enabling ? "primary" : transition.command === "quick_stop" || transition.command === "disable_voltage" ? "danger" : "",
        disabled: () => props.busy.val || (enabling && !valueOf(props.armed)),
        "data-testid": `transition-${transition.command}`,
        title: () => (enabling && !valueOf(props.armed) ? "Arm the axis first (Controller): motion needs an armed controller" : title),
        onclick: () => props.onCommand(transition.command),
      }, COMMAND_LABELS[transition.command]);
    }));
  });
}

/** The enumeration of 0x6060, following the active mode until the user picks one, and Set mode. */
function modeSelector(mode: Entry, props: DeviceControlProps): HTMLElement[] {
  const editor = enumEditor(mode.variable, {
    value: props.activeMode,
    unknownLabel: (value) => `${value} (no mode)`,
    attrs: { "data-testid": "dashboard-mode-select", "aria-label": "Mode of operation" },
    onSubmit: (raw) => {
      const select = editor.element as HTMLSelectElement;
      props.onSetMode(Number(raw), select.selectedOptions[0]?.text ?? String(raw));
    },
  });
  return [editor.element, h("button", { "data-testid": "dashboard-set-mode", onclick: () => editor.submit() }, "Set mode")];
}
