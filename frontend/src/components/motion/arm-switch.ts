/**
 * The explicit arm switch before any motion (docs/motion-safety.md): on, this page is the axis's controller and the
 * motion buttons work; off, nothing here can move the axis (and an enabled axis gets a quick stop).
 */

import { h, valueOf, type Bindable } from "../../lib/dom";

export interface ArmSwitchProps {
  armed: Bindable<boolean>;
  /** Another client holds the axis: the switch cannot take it (the Controller panel can ask for it). */
  heldElsewhere: Bindable<boolean>;
  busy: Bindable<boolean>;
  onArm(): void;
  onRelease(): void;
}

export function armSwitch(props: ArmSwitchProps): HTMLElement {
  const toggle = (event: Event) => {
    const on = (event.target as HTMLInputElement).checked;
    if (on) props.onArm();
    else props.onRelease();
  };
  return h("label", { class: "field arm-switch", title: "Motion needs this page to be the axis's armed controller" },
    h("input", {
      type: "checkbox", role: "switch", "data-testid": "motion-arm", checked: props.armed,
      disabled: () => valueOf(props.busy) || valueOf(props.heldElsewhere), onchange: toggle,
    }),
    () => (valueOf(props.armed) ? "Armed: this page controls the axis" : valueOf(props.heldElsewhere) ? "Armed by another client" : "Arm before any motion"));
}
