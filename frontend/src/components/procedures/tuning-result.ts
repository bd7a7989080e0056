/**
 * An auto-tuning's result: the identified plant (total inertia and its ratio to the motor's, viscous and Coulomb
 * friction, constant load torque — published by the drive in 0x3428), the gains before → after with their meaning,
 * the verification steps plotted with rise time, overshoot and settling time, and Undo (the gains before written
 * back, validated by the server before any write).
 */

import { isTuningCheck, type Identified, type PerAmpere, type ProcedureResult } from "../../client/procedures";
import { h, state, type Child } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { errorText, messageView, type Message } from "../ui";
import type { ProceduresModel } from "./model";
import { changeTable, doneLine } from "./results";
import { stepView } from "./step-plot";

export function identifiedRows(identified: Identified): [string, string, string][] {
  const perAmpere = identified.per_ampere;
  if (perAmpere) return perAmpereRows(perAmpere);
  return [
    ["inertia", "Total inertia seen by the motor", sig(identified.inertia_kgm2, "kg·m²")],
    ["ratio", "Ratio to the motor's inertia", identified.inertia_ratio === null ? "— (motor inertia not known)" : `${sig(identified.inertia_ratio)} ×`],
    ["viscous", "Viscous friction", sig(identified.viscous_friction_nms_per_rad, "N·m·s/rad")],
    ["coulomb", "Coulomb friction", sig(identified.coulomb_friction_nm, "N·m")],
    ["load", "Constant load torque", sig(identified.load_torque_nm, "N·m")],
  ];
}

/** A drive without a torque constant: the plant divided by Kt (multiply by the motor's N·m/A for physical units). */
function perAmpereRows(plant: PerAmpere): [string, string, string][] {
  return [
    ["inertia", "Total inertia / torque constant", sig(plant.inertia_as2_per_rad, "A·s²/rad")],
    ["viscous", "Viscous friction / torque constant", sig(plant.viscous_friction_as_per_rad, "A·s/rad")],
    ["coulomb", "Coulomb friction / torque constant", sig(plant.coulomb_friction_a, "A")],
    ["load", "Constant load torque / torque constant", sig(plant.load_torque_a, "A")],
  ];
}

export function tuningResult(model: ProceduresModel, result: ProcedureResult): Child {
  const verification = isTuningCheck(result.verification) ? result.verification : null;
  return [
    doneLine(result),
    result.identified ? [h("strong", null, "Identified plant"),
      h("table", { class: "data kv", "data-testid": "tuning-identified" }, h("tbody", null, identifiedRows(result.identified).map(([key, label, value]) =>
        h("tr", null, h("td", null, label), h("td", { class: "num", "data-testid": `identified-${key}` }, value)))))] : null,
    result.gains ? [h("strong", null, "Gains"), changeTable(result.gains, "tuning-gains"), undoButton(model, result.gains.before)] : null,
    verification?.speed_step ? stepView(verification.speed_step, "Verification: speed step", "verify-speed") : null,
    verification?.position_step ? stepView(verification.position_step, "Verification: position step", "verify-position") : null,
  ];
}

function undoButton(model: ProceduresModel, before: Record<string, number>): HTMLElement {
  const message = state<Message | null>(null);
  const busy = state(false);
  const undo = async () => {
    busy.val = true;
    try {
      const answer = await model.client.undo(model.where.bus, model.where.node, before);
      const values = Object.entries(answer.gains).map(([name, raw]) => `${name} ${raw}`).join(", ");
      message.val = { text: `The gains before the tuning are back on the drive (read back: ${values}).`, tone: "ok", testid: "undo-done" };
    } catch (error) {
      message.val = { text: `Undo: ${errorText(error)}`, tone: "error", testid: "undo-failed" };
    } finally {
      busy.val = false;
    }
  };
  return h("div", null,
    h("button", { "data-testid": "tuning-undo", disabled: busy, title: "Write the gains of the Before column back to the drive", onclick: () => void undo() }, "Undo: previous gains → drive"),
    messageView(message));
}
