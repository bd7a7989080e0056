/**
 * Auto-tuning of one axis (tab "Auto-tuning", manual §1.8.16 / §4.11): the options as the manual names them, the
 * safety checklist, start / abort / progress, and the result — the identified plant, the gains before → after with
 * their meaning, the verification step(s) plotted, Undo — and the results kept in the project; beside it the tool's own
 * identification, for a drive without auto-tuning (encoTRive) or as a cross-check (docs/identification.md).
 */

import type { TuningOptions } from "../client/procedures";
import { identificationPanel } from "../components/identification/panel";
import { brakeRemedy } from "../components/procedures/brake";
import type { ProceduresModel } from "../components/procedures/model";
import { runnerPanel } from "../components/procedures/runner";
import { savedPanel } from "../components/procedures/saved";
import { tuningResult } from "../components/procedures/tuning-result";
import { h, state, type State } from "../lib/dom";
import type { AxisContext, AxisViewPage } from "./axis";
import { procedureView } from "./procedures";

type Choice<K extends keyof TuningOptions> = [TuningOptions[K], string][];

const BANDWIDTHS: Choice<"bandwidth"> = [[50, "Low: 50 Hz"], [75, "Medium: 75 Hz"], [100, "High: 100 Hz"]];
const FILTERS: Choice<"filter"> = [
  ["standard", "Standard"],
  ["anti-resonance", "Anti-resonance (loud noise from an elastic coupling)"],
  ["max-stiffness", "Maximum stiffness (best disturbance rejection; only without resonance)"],
];
const SPEED_FILTERS: Choice<"speed_filter"> = [["auto", "Auto-select"], ["0.5", "0.5 ms"], ["1", "1 ms"], ["2", "2 ms"]];
const MODES: Choice<"mode"> = [
  ["min-following-error", "Minimum following error (all feed-forward gains computed)"],
  ["min-overshoot", "Minimum position overshoot (feed-forward gains 0; the position lags)"],
];

export function tuningView(context: AxisContext): Promise<AxisViewPage> {
  return procedureView(context, ({ model }) => [
    tuningPanel(model),
    identificationPanel(model),
    savedPanel(model, ["auto_tuning"], "Auto-tuning results kept in the project"),
  ]);
}

function select<K extends keyof TuningOptions>(testid: string, value: State<TuningOptions[K]>, choices: Choice<K>): HTMLSelectElement {
  return h("select", {
    "data-testid": testid, value: () => String(value.val),
    onchange: (event: Event) => {
      const picked = (event.target as HTMLSelectElement).value;
      value.val = choices.find(([option]) => String(option) === picked)![0];
    },
  }, choices.map(([option, label]) => h("option", { value: String(option) }, label)));
}

function tuningPanel(model: ProceduresModel): HTMLElement {
  const bandwidth = state<TuningOptions["bandwidth"]>(75);
  const filter = state<TuningOptions["filter"]>("standard");
  const speedFilter = state<TuningOptions["speed_filter"]>("auto");
  const mode = state<TuningOptions["mode"]>("min-following-error");
  const verify = state(true);
  const row = (label: string, field: HTMLElement, note = "") => [h("label", null, label), h("span", null, field, note ? h("span", { class: "muted" }, ` ${note}`) : null)];
  const fields = h("div", { class: "grid", style: { gridTemplateColumns: "auto 1fr", gap: "6px 12px", alignItems: "center" } },
    row("Bandwidth (closed speed loop)", select("tune-bandwidth", bandwidth, BANDWIDTHS)),
    row("Filter type", select("tune-filter", filter, FILTERS)),
    row("Speed measurement filter", select("tune-speed-filter", speedFilter, SPEED_FILTERS), "noise against gain; auto lets the tuning choose"),
    row("Position loop requirement", select("tune-mode", mode, MODES)),
    row("Verification", h("label", { class: "check" },
      h("input", { type: "checkbox", checked: verify, "data-testid": "tune-verify", onchange: (event: Event) => (verify.val = (event.target as HTMLInputElement).checked) }),
      " a speed step (and a position step in a position mode) recorded afterwards")));
  return runnerPanel({
    model, name: "auto_tuning", title: "Auto-tuning ('atun')", verify, startLabel: "Start auto-tuning",
    intro: ["Identifies the motor and load (inertia, friction, load torque) and computes the gains. The controller type is the ",
      "operating mode: in profile velocity only the speed gains (the position gain becomes 0, the motor cannot move in PP); in a ",
      "position mode the speed and position gains. The drive may be disabled, or enabled at standstill (vertical load). If the ",
      "motor is noisy afterwards: check the rigidity, tune with a lower bandwidth, then with the anti-resonance filter."],
    fields: h("div", null, fields, brakeRemedy(model, "auto_tuning")),
    options: () => ({ bandwidth: bandwidth.rawVal, filter: filter.rawVal, speed_filter: speedFilter.rawVal, mode: mode.rawVal }),
    result: (result) => tuningResult(model, result),
  });
}
