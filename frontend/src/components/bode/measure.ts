/**
 * The "Measure" panel: a plant or closed-loop frequency response measured by the drive as a server job
 * (`POST …/frequency-response`, docs/frequency-response.md) with its safety settings — amplitude, base speed (the
 * axis never crosses zero speed), position window, current limit — saved under the axis and shown at once; the
 * motor turns, so this page must be the axis's armed controller. After "Write these gains" the page measures the
 * closed loop again and sets the re-measured bandwidth beside the predicted one.
 */

import { measureApi, measureProgress, type MeasureBody } from "../../client/frequency";
import { runJob } from "../../client/jobs";
import type { LiveHub } from "../../client/live";
import { h, state, type State } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { errorText } from "../ui";
import { refreshSaved, toggleShown, usePlant, type BodeModel } from "./model";

export interface MeasureState {
  settings: State<Omit<MeasureBody, "project" | "axis">>;
  progress: State<{ stage: string; fraction: number } | null>;
  /** the what-if bandwidth the written gains were predicted to give, and what the closed loop measured after */
  check: State<{ predictedHz: number | null; measuredHz: number | null; hint?: string } | null>;
  abort: AbortController | null;
}

export function measureState(): MeasureState {
  return {
    settings: state<Omit<MeasureBody, "project" | "axis">>({ loop: "plant", from_hz: 5, to_hz: 400, points: 60, amplitude_pct: null, base_speed_rad_s: 10, position_window: 10, current_limit_a: null, periods: 4 }),
    progress: state(null), check: state(null), abort: null,
  };
}

/** Measure with the panel's settings (`loop` overrides the chosen one); the result is saved, listed and shown. */
export async function measure(model: BodeModel, live: LiveHub, run: MeasureState, loop?: "plant" | "closed"): Promise<number | null> {
  const { bus, node, project, axis } = model.where;
  const body: MeasureBody = { ...run.settings.rawVal, ...(loop ? { loop } : {}), project, axis };
  run.abort = new AbortController();
  run.progress.val = { stage: "starting", fraction: 0 };
  try {
    const job = await runJob(live, () => measureApi.start(bus, node, body), (event) => {
      const progress = measureProgress(event);
      if (progress) run.progress.val = progress;
    }, run.abort.signal);
    const result = job.result;
    if (job.state !== "done" || !result) throw new Error(job.error ?? `the measurement ended ${job.state}`);
    if (result.aborted) model.message.val = { text: `Measurement aborted: ${result.aborted}`, tone: "warn", testid: "bode-aborted" };
    await refreshSaved(model);
    if (result.saved) await (result.loop === "plant" ? usePlant(model, result.saved) : toggleShown(model, result.saved, true));
    return result.markers?.bandwidth_hz ?? null;
  } catch (error) {
    model.message.val = { text: `Measurement: ${errorText(error)}`, tone: "error", testid: "bode-measure-error" };
    return null;
  } finally {
    run.progress.val = null;
    run.abort = null;
  }
}

/** After "Write these gains": the closed loop measured again, its bandwidth set beside the prediction. */
export async function remeasure(model: BodeModel, live: LiveHub, run: MeasureState, predictedHz: number | null): Promise<void> {
  run.check.val = { predictedHz, measuredHz: null };
  model.view.val = "closed";
  const measuredHz = await measure(model, live, run, "closed");
  run.check.val = { predictedHz, measuredHz };
}

type Setting = "from_hz" | "to_hz" | "points" | "amplitude_pct" | "base_speed_rad_s" | "position_window" | "current_limit_a" | "periods";

function numberField(run: MeasureState, key: Setting, label: string, unit: string): HTMLElement {
  return h("label", { class: "field" }, `${label} [${unit}]`, h("input", {
    type: "number", "data-testid": `measure-${key}`, value: String(run.settings.rawVal[key] ?? ""), placeholder: "default",
    oninput: (event: Event) => {
      const text = (event.target as HTMLInputElement).value.trim();
      run.settings.val = { ...run.settings.rawVal, [key]: text === "" ? null : Number(text) };
    },
  }));
}

function checkLine(run: MeasureState): HTMLElement | null {
  const check = run.check.val;
  if (!check) return null;
  const { predictedHz, measuredHz, hint } = check;
  const deviation = predictedHz && measuredHz ? ` (${sig((100 * (measuredHz - predictedHz)) / predictedHz, "%")})` : "";
  const measured = hint ?? `re-measured ${measuredHz === null ? "…" : sig(measuredHz, "Hz")}${deviation}.`;
  return h("div", { class: `message ${hint ? "warn" : "ok"}`, "data-testid": "bode-check" },
    h("span", { "data-testid": "bode-check-predicted" }, `Predicted bandwidth ${sig(predictedHz, "Hz")}`), ", ",
    h("span", { "data-testid": "bode-check-measured" }, measured));
}

export function measurePanel(model: BodeModel, live: LiveHub, run: MeasureState, armed: () => boolean): HTMLElement {
  const loopSelect = h("select", { "data-testid": "measure-loop", onchange: () => (run.settings.val = { ...run.settings.rawVal, loop: loopSelect.value as "plant" | "closed" }) },
    h("option", { value: "plant" }, "Plant (torque → speed)"), h("option", { value: "closed" }, "Closed speed loop"));
  const busy = () => run.progress.val !== null;
  return h("section", { class: "panel", "data-testid": "measure-panel" }, h("h2", null, "Measure"),
    h("div", { class: "panel-body grid", style: { gap: "6px" } },
      h("div", { class: "muted" }, "The motor turns at the base speed with the multi-sine on top; the drive stops (quick stop) when the axis leaves the position window or exceeds the current limit."),
      h("label", { class: "field" }, "Loop", loopSelect),
      h("div", { class: "grid", style: { gridTemplateColumns: "1fr 1fr", gap: "6px" } },
        numberField(run, "from_hz", "From", "Hz"), numberField(run, "to_hz", "To", "Hz"), numberField(run, "points", "Points", "lines"),
        numberField(run, "amplitude_pct", "Amplitude", "%"), numberField(run, "base_speed_rad_s", "Base speed", "rad/s"),
        numberField(run, "position_window", "Position window", "rev"), numberField(run, "current_limit_a", "Current limit", "A"),
        numberField(run, "periods", "Periods averaged", "count")),
      h("div", { class: "toolbar" },
        h("button", { class: "primary", "data-testid": "measure-start", disabled: () => busy() || !armed(),
          title: () => (armed() ? "Measure now" : "Arm the axis first (Controller panel): the motor turns"),
          onclick: () => {
            model.message.val = null;
            void measure(model, live, run);
          } }, "Measure"),
        h("button", { "data-testid": "measure-abort", disabled: () => !busy(), onclick: () => run.abort?.abort() }, "Abort")),
      () => (run.progress.val ? h("div", { "data-testid": "measure-progress" }, h("progress", { max: "1", value: String(run.progress.val.fraction) }),
        ` ${run.progress.val.stage}`) : null),
      () => checkLine(run)));
}
