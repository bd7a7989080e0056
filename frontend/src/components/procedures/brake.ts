/**
 * The remedy for auto-tuning's "Holding brake released" precondition (manual §1.8.16: auto-tuning does not control
 * the brake): manual brake control — digital output bitmask 0x60FE,2 bit 0 = 1, then the brake output 0x60FE,1
 * bit 0 = 0 (released) — after a confirmation, since a released brake lets a vertical axis fall.
 */

import { driveApi } from "../../client/drives";
import { h, state } from "../../lib/dom";
import { confirmAction, errorText, messageView, type Message } from "../ui";
import { infoOf, refresh, type ProceduresModel } from "./model";

const OUTPUTS = "0x60FE,1";
const MASK = "0x60FE,2";
const BRAKE_BIT = 1;

/** Shown while the drive reports the brake applied for `procedure`. */
export function brakeRemedy(model: ProceduresModel, procedure: string): HTMLElement {
  const message = state<Message | null>(null);
  const release = async () => {
    const text = "Manual brake control releases the holding brake now: a vertical or driving load can move. Release it?";
    if (!(await confirmAction("Release the holding brake", text, "Release brake", true))) return;
    try {
      const { bus, node } = model.where;
      const mask = Number((await driveApi.read(bus, node, MASK)).raw);
      await driveApi.writeKey(bus, node, MASK, mask | BRAKE_BIT);
      const outputs = Number((await driveApi.read(bus, node, OUTPUTS)).raw);
      await driveApi.writeKey(bus, node, OUTPUTS, outputs & ~BRAKE_BIT);
      message.val = { text: "Brake released by manual brake control (0x60FE,2 bit 0 = 1, 0x60FE,1 bit 0 = 0).", tone: "ok", testid: "brake-released" };
      await refresh(model);
    } catch (error) {
      message.val = { text: `Brake: ${errorText(error)}`, tone: "error", testid: "brake-failed" };
    }
  };
  return h("div", null, () => {
    const applied = infoOf(model, procedure)?.preconditions.some((condition) => condition.name === "brake_released" && !condition.ok);
    return applied ? h("div", { class: "toolbar" },
      h("button", { "data-testid": "brake-release", onclick: () => void release() }, "Release the brake (manual brake control)…"),
      h("span", { class: "muted" }, "or run the tuning enabled at standstill")) : null;
  }, messageView(message));
}
