/**
 * Live roll mode on the scope page (docs/scope.md §8): the channels of the capture form streamed through TPDOs at
 * the server's SYNC; the bus budget shown before the start (an over-subscribed roll is refused with the server's
 * reason), Start / Stop, "record while rolling" (the samples saved in the project as a capture at the end), the
 * plot of the last seconds, the samples received, the samples lost and the display latency, and every gap listed.
 */

import type { CapturePlan } from "../../client/scope";
import { effect, h, type Scope, type State } from "../../lib/dom";
import { formatNumber } from "../../lib/numbers";
import type { RollGap } from "../../lib/roll";
import { messageView } from "../ui";
import type { ScopeModel } from "./model";
import { rollPlot, type RollProgress } from "./rollplot";
import { checkBudget, createRoll, disposeRoll, startRoll, stopRoll, type RollModel } from "./rollmodel";

/** How long the form must be still before its budget is checked again. */
const CHECK_DELAY_MS = 300;

export function rollView(model: ScopeModel, scope: Scope): { element: HTMLElement; dispose(): void } {
  const roll = createRoll();
  const plot = rollPlot(roll, scope);
  let timer: ReturnType<typeof setTimeout> | undefined;
  scope.run(() => effect(() => {
    void [model.draft.channels.val, roll.period.val];
    clearTimeout(timer);
    timer = setTimeout(() => void checkBudget(model, roll), CHECK_DELAY_MS);
  }));
  const element = scope.run(() => h("section", { class: "panel", "data-testid": "scope-roll" },
    h("div", { class: "panel-body grid", style: { gap: "8px" } },
      h("div", { class: "toolbar" }, h("strong", null, "Live roll"), ...rollControls(model, roll), statusView(roll, plot.progress)),
      h("div", { class: "muted", "data-testid": "scope-roll-budget" }, () => budgetText(roll.budget.val)),
      messageView(roll.message),
      plot.element,
      gapList(plot.gaps))));
  return {
    element,
    dispose: () => {
      clearTimeout(timer);
      disposeRoll(roll);
      plot.dispose();
    },
  };
}

function rollControls(model: ScopeModel, roll: RollModel): HTMLElement[] {
  const period: HTMLInputElement = h("input", { "data-testid": "scope-roll-period", value: roll.period, style: { width: "70px" }, oninput: () => (roll.period.val = period.value) });
  const record: HTMLInputElement = h("input", { type: "checkbox", "data-testid": "scope-roll-record", checked: roll.record, onchange: () => (roll.record.val = record.checked) });
  return [
    h("label", null, "Period ", period, " µs"),
    h("label", { title: "Keep every sample (up to the first gap) and save them in the project as a capture at the end" }, record, " record while rolling"),
    h("button", { class: "primary", "data-testid": "scope-roll-start", disabled: () => roll.running.val, onclick: () => void startRoll(model, roll) }, "Start roll"),
    h("button", { "data-testid": "scope-roll-stop", disabled: () => !roll.running.val, onclick: () => stopRoll(roll) }, "Stop roll"),
  ];
}

function statusView(roll: RollModel, progress: State<RollProgress>): HTMLElement {
  return h("span", { class: "pill", "data-testid": "scope-roll-status" }, () => {
    const shown = progress.val;
    const latency = Number.isFinite(shown.latencyMs) ? `, latency ${Math.max(0, Math.round(shown.latencyMs))} ms` : "";
    return [h("span", { class: `dot ${roll.running.val ? "warn" : "ok"}` }),
      `${roll.running.val ? "rolling" : "stopped"}: ${shown.received} samples, ${shown.lost} lost${latency}`];
  });
}

/** The bus budget of the roll as the server plans it: frames/s and the load they make against the bit rate. */
export function budgetText(plan: CapturePlan | null): string {
  const stream = plan?.stream;
  if (!plan || !stream) return "Bus budget: checking…";
  const rate = `${formatNumber(stream.bitrate / 1000, 4)} kbit/s${stream.bitrate_assumed ? " (assumed)" : ""}`;
  return `Bus budget: ${plan.channels.length} channels at ${formatNumber(stream.rate_hz, 6)} Hz on node${stream.nodes.length > 1 ? "s" : ""} ` +
    `${stream.nodes.join(", ")}: ${formatNumber(stream.frames_per_s, 6)} frames/s, bus load ${formatNumber(stream.bus_load * 100, 3)} % of ${rate} (limit 70 %)`;
}

function gapList(listed: State<RollGap[]>): HTMLElement {
  return h("div", { "data-testid": "scope-roll-gaps" }, () => {
    const gaps = listed.val;
    if (gaps.length === 0) return h("span", { class: "muted" }, "No gap: every sample arrived.");
    return h("ul", { class: "message error" }, gaps.map((gap) => h("li", { "data-testid": "scope-roll-gap" }, gapText(gap))));
  });
}

export function gapText(gap: RollGap): string {
  return `samples ${gap.from}..${gap.to - 1} lost (${gap.to - gap.from}): ${gap.reason}`;
}
