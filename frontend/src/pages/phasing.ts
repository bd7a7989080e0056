/**
 * Phasing of one axis (tab "Phasing"): auto-phasing ('apha': pole pairs, phase order, position sensor offset,
 * manual §1.8.13 / §4.2) with its verification move, and motor phasing ('mcal': the offset only) for an
 * incremental encoder without Hall sensors, which the drive needs after every 24 V power-up (warning bit 30).
 */

import { driveApi } from "../client/drives";
import { run, type ProceduresModel } from "../components/procedures/model";
import { phasingResult } from "../components/procedures/results";
import { runnerPanel } from "../components/procedures/runner";
import { savedPanel } from "../components/procedures/saved";
import { effect, h, state } from "../lib/dom";
import { needsMotorPhasing } from "../lib/procedures";
import type { AxisContext, AxisViewPage } from "./axis";
import { procedureView } from "./procedures";

export function phasingView(context: AxisContext): Promise<AxisViewPage> {
  return procedureView(context, ({ model }) => [
    autoPhasing(model),
    h("div", null, () => (model.procedures.val?.some((p) => p.name === "motor_phasing") ? motorPhasing(model) : null)),
    savedPanel(model, ["auto_phasing", "motor_phasing"], "Phasing results kept in the project"),
  ]);
}

function autoPhasing(model: ProceduresModel): HTMLElement {
  const verify = state(true);
  return runnerPanel({
    model, name: "auto_phasing", title: "Auto-phasing", verify, startLabel: "Start auto-phasing",
    intro: ["Identifies the pole pairs, the phase order and the position sensor offset (the mechanical shift between the ",
      "motor and its resolver or absolute encoder). The drive injects a current and turns the field: the rotor follows ",
      "through up to one revolution. Calculate the current loop first: on an uncommissioned drive auto-phasing fails before 'calc'. ",
      "With Hall sensors only, enter the pole pairs by hand first; not possible in sensorless control."],
    fields: h("label", { class: "check" },
      h("input", { type: "checkbox", checked: verify, "data-testid": "auto_phasing-verify", onchange: (event: Event) => (verify.val = (event.target as HTMLInputElement).checked) }),
      " Verification move afterwards: torque per ampere must reach 98 % of the expected value"),
    result: phasingResult,
  });
}

function motorPhasing(model: ProceduresModel): HTMLElement {
  const warning = state(false);
  // Read when the panel is built and again after each run: a done motor phasing clears the warning.
  effect(() => {
    void run(model, "motor_phasing").ended.val;
    void driveApi.faults(model.where.bus, model.where.node)
      .then((report) => (warning.val = needsMotorPhasing(report.warnings)), () => undefined);
  });
  return runnerPanel({
    model, name: "motor_phasing", title: "Motor phasing (incremental encoder without Hall sensors)", startLabel: "Start motor phasing",
    intro: ["Finds the sensor offset again with the known pole pairs and phase order. An incremental encoder without Hall ",
      "sensors needs it after every 24 V power-up and after an encoder counting, cable or zero-mark fault; until then the ",
      "drive sets warning bit 30 \"Motor phasing init not OK\" and refuses Enable operation. Run auto-phasing once before."],
    fields: h("div", { "data-testid": "motor-phasing-warning" }, () => (warning.val
      ? h("div", { class: "message warn" }, "The drive reports warning bit 30: motor phasing is needed now.")
      : null)),
    result: phasingResult,
  });
}
