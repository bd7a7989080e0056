/**
 * Current loop of one axis (tab "Current loop", manual §1.8.8–1.8.11): the motor inductance and the drive current
 * → the current loop calculation 'calc' (gains before → after, and the limits it sets), the current-limit
 * calculation with the manual's rule and ranges, and the I²t protection (Fusing while commissioning) with its
 * timing formulas. The drive's values are read again after every run.
 */

import { calcFields, currentValues, i2tPanel, limitsFields, type CurrentValues } from "../components/procedures/current";
import { run, type ProceduresModel } from "../components/procedures/model";
import { currentLoopResult } from "../components/procedures/results";
import { runnerPanel } from "../components/procedures/runner";
import { savedPanel } from "../components/procedures/saved";
import { effect, h } from "../lib/dom";
import type { AxisContext, AxisViewPage } from "./axis";
import { procedureView } from "./procedures";

export function currentLoopView(context: AxisContext): Promise<AxisViewPage> {
  return procedureView(context, ({ model }) => {
    const current = currentValues(model, context.dictionary);
    effect(() => {
      void run(model, "current_loop").ended.val;
      void run(model, "current_limits").ended.val;
      void current.reload();
    });
    return [
      h("div", null, () => (current.error.val ? h("div", { class: "message error" }, `Drive values: ${current.error.val}`) : null)),
      calcPanel(model, current),
      limitsPanel(model, current),
      i2tPanel(model, current),
      savedPanel(model, ["current_loop", "current_limits"], "Current loop results kept in the project"),
    ];
  });
}

function calcPanel(model: ProceduresModel, current: CurrentValues): HTMLElement {
  const fields = calcFields(current);
  return runnerPanel({
    model, name: "current_loop", title: "Current loop calculation ('calc')", startLabel: "Calculate current loop",
    intro: ["Enter the total phase-to-phase inductance (the motor's plus any external series inductors; it is written to ",
      "the motor data first) and choose the bandwidth. Calculate again when inductors are added; a changed supply voltage ",
      "needs no new calculation (the drive adapts the gains). Run this before auto-phasing."],
    fields: fields.element,
    options: fields.options,
    provides: fields.provides,
    result: currentLoopResult,
  });
}

function limitsPanel(model: ProceduresModel, current: CurrentValues): HTMLElement {
  return runnerPanel({
    model, name: "current_limits", title: "Current limits", startLabel: "Calculate current limits",
    intro: "The drive computes its max and rated current from the motor's peak and stall currents and its own rating (0x3412).",
    fields: limitsFields(current),
    result: currentLoopResult,
  });
}
