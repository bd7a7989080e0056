/**
 * The axis's controller (docs/motion-safety.md): who answers for this axis, and the one way to become it. Motion —
 * enabling, a target while enabled, phasing — needs this page to have armed the axis; another page sees who holds
 * it and may ask for it (the holder gets the question here and may release) or, at the Expert level, take it over.
 */

import { heldByMe, holderText, type AxisControl } from "../../client/control";
import { h, valueOf, type Bindable, type State } from "../../lib/dom";

export interface ControllerProps {
  /** Who holds the axis; null until the server answered. */
  control: State<AxisControl | null>;
  /** The user who asked this page, the controller, for the axis (null: nobody asks). */
  askedBy: State<string | null>;
  busy: State<boolean>;
  /** The caller's level allows a take-over (Expert and above). */
  mayTakeOver: Bindable<boolean>;
  onArm(): void;
  onRelease(): void;
  onRequest(): void;
  onTakeOver(): void;
}

export function controllerPanel(props: ControllerProps): HTMLElement {
  return h("section", { class: "panel", "data-testid": "controller" },
    h("h2", null, "Controller"),
    h("div", { class: "panel-body" },
      h("div", { class: "toolbar" },
        h("span", { class: () => `dot ${tone(props.control.val)}` }),
        h("span", { "data-testid": "controller-holder" }, () => holderText(props.control.val))),
      h("div", { class: "toolbar", style: { marginTop: "8px" } }, () => actions(props)),
      () => request(props)));
}

function tone(control: AxisControl | null): string {
  if (!control?.holder) return "idle";
  return heldByMe(control) ? "ok" : "warn";
}

function actions(props: ControllerProps): HTMLElement[] {
  const control = props.control.val;
  const button = (testid: string, label: string, onclick: () => void, kind = "", title = "") =>
    h("button", { class: kind, disabled: props.busy, "data-testid": testid, title, onclick }, label);
  if (!control) return [];
  if (!control.holder) {
    return [button("control-arm", "Arm", props.onArm, "primary", "Make this page the axis's controller: motion needs it")];
  }
  if (heldByMe(control)) {
    return [button("control-release", "Release", props.onRelease, "", "Disarm; an enabled axis gets a quick stop")];
  }
  const asked = button("control-request", "Ask for it", props.onRequest, "", "The controller is asked to release the axis");
  const takeOver = button("control-take-over", "Take over", props.onTakeOver, "danger", "Become the controller at once (logged)");
  return valueOf(props.mayTakeOver) ? [asked, takeOver] : [asked];
}

function request(props: ControllerProps): HTMLElement | null {
  const user = props.askedBy.val;
  if (!user || !heldByMe(props.control.val)) return null;
  return h("div", { class: "message", "data-testid": "controller-asked", style: { marginTop: "8px" } },
    `${user} asks for this axis. `,
    h("button", { class: "small", "data-testid": "control-hand-over", onclick: () => props.onRelease() }, "Release it"));
}
