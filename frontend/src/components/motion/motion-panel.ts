/**
 * Quick test · motion (manual §1.8.19): the arm switch, a jog, moves (relative or absolute), homing with the
 * device's methods and the manual's description of each (in CiA 402's modes PV, PP, HM; on a TTA-PRO by its control
 * word), the axis's limits (small by default, raised here) and what the last motion did. Every button is hold-to-run (`hold-button.ts`).
 */

import { armSwitch } from "./arm-switch";
import { holdButton } from "./hold-button";
import { homingChoice, motionText, type QuickMotion } from "./model";
import { h, state, valueOf, type Bindable, type State } from "../../lib/dom";

export interface MotionPanelProps {
  model: QuickMotion;
  armed: Bindable<boolean>;
  heldElsewhere: Bindable<boolean>;
  busy: Bindable<boolean>;
  onArm(): void;
  onRelease(): void;
  /** The motions run in CiA 402 modes (PV, PP, HM) and say so; false: by control-word bits (the TTA-PRO). */
  modes?: boolean;
}

function numberField(label: string, testid: string, value: State<string>, width = "90px"): HTMLElement {
  return h("label", { class: "field" }, label,
    h("input", {
      type: "number", step: "any", "data-testid": testid, "aria-label": label, style: { width }, value,
      oninput: (event: Event) => (value.val = (event.target as HTMLInputElement).value),
    }));
}

/** The number typed, or the refusal; an empty optional field is null. */
function parsed(label: string, text: string, optional = false): number | null | string {
  if (optional && text.trim() === "") return null;
  const value = Number(text);
  return text.trim() !== "" && Number.isFinite(value) ? value : `${label}: "${text}" is no number`;
}

export function motionPanel(props: MotionPanelProps): HTMLElement {
  const locked = () => !valueOf(props.armed) || valueOf(props.busy);
  const { model } = props;
  return h("div", { class: "grid motion-test", style: { gap: "8px" }, "data-testid": "motion-test" },
    h("div", { class: "toolbar" },
      armSwitch(props),
      h("span", { class: "muted", "data-testid": "motion-state" }, () => motionText(model.motion.val))),
    jogRow(model, locked, props.modes ? "Jog (PV)" : "Jog"),
    moveRow(model, locked, props.modes ? "Move (PP)" : "Move"),
    homingRow(model, locked, props.modes ? "Homing (HM)" : "Homing"),
    limitsRow(model),
    () => (model.error.val ? h("div", { class: "message error", "data-testid": "motion-error" }, model.error.val) : null));
}

function held(model: QuickMotion, locked: () => boolean, label: string, testid: string, start: () => string | null): HTMLButtonElement {
  return holdButton({
    label, testid, disabled: locked, title: "Hold to run: the axis stops when you let go",
    onPress: () => {
      const refusal = start();
      if (refusal) model.error.val = refusal;
    },
    onRelease: () => model.release(),
  });
}

function jogRow(model: QuickMotion, locked: () => boolean, title: string): HTMLElement {
  const velocity = state("60");
  const jog = (sign: number) => () => {
    const value = parsed("Velocity", velocity.rawVal);
    if (typeof value !== "number") return value;
    void model.jog(sign * value);
    return null;
  };
  return h("div", { class: "toolbar" },
    h("strong", null, title),
    numberField("Velocity [rpm]", "jog-velocity", velocity),
    held(model, locked, "◀ Hold to jog −", "jog-minus", jog(-1)),
    held(model, locked, "Hold to jog + ▶", "jog-plus", jog(1)));
}

function moveRow(model: QuickMotion, locked: () => boolean, title: string): HTMLElement {
  const distance = state("4096");
  const velocity = state("");
  const absolute = state(false);
  const move = () => {
    const to = parsed("Distance", distance.rawVal);
    const speed = parsed("Velocity", velocity.rawVal, true);
    if (typeof to !== "number") return to;
    if (typeof speed === "string") return speed;
    void model.move(to, absolute.rawVal, speed);
    return null;
  };
  return h("div", { class: "toolbar" },
    h("strong", null, title),
    numberField("Distance [user units]", "move-distance", distance, "110px"),
    h("label", { class: "field" },
      h("input", { type: "checkbox", "data-testid": "move-absolute", checked: absolute, onchange: (event: Event) => (absolute.val = (event.target as HTMLInputElement).checked) }),
      "Absolute"),
    numberField("Velocity [rpm]", "move-velocity", velocity),
    held(model, locked, "Hold to move", "move-run", move));
}

function homingRow(model: QuickMotion, locked: () => boolean, title: string): HTMLElement {
  const method = state("35");
  const velocity = state("");
  const chosen = () => homingChoice(model.methods.val, method.val);
  const described = () => model.methods.val.find((item) => String(item.method) === chosen())?.description ?? "";
  const home = () => {
    const speed = parsed("Velocity", velocity.rawVal, true);
    if (typeof speed === "string") return speed;
    void model.home(Number(homingChoice(model.methods.rawVal, method.rawVal)), speed);
    return null;
  };
  const options = () => model.methods.val.map((item) =>
    h("option", { value: String(item.method), title: item.description }, `${item.method} — ${item.description}`));
  return h("div", { class: "grid", style: { gap: "4px" } },
    h("div", { class: "toolbar" },
      h("strong", null, title),
      h("label", { class: "field" }, "Method",
        h("select", { "data-testid": "homing-method", style: { maxWidth: "280px" }, value: chosen, onchange: (event: Event) => (method.val = (event.target as HTMLSelectElement).value) }, options)),
      numberField("Search speed [rpm]", "homing-velocity", velocity),
      held(model, locked, "Hold to home", "homing-run", home)),
    h("span", { class: "muted", "data-testid": "homing-description" }, described));
}

function limitsRow(model: QuickMotion): HTMLElement {
  const open = state(false);
  const shown = () => {
    const limits = model.limits.val;
    return limits ? `Limits: ${limits.velocity_rpm} rpm · ${limits.distance_revolutions} rev per move · ${limits.seconds} s` : "Limits: …";
  };
  return h("div", { class: "toolbar" },
    h("span", { class: "muted", "data-testid": "motion-limits" }, shown),
    h("button", { class: "small", "data-testid": "limits-edit", onclick: () => (open.val = !open.val) }, "Raise limits…"),
    () => (open.val ? limitsForm(model, () => (open.val = false)) : null));
}

function limitsForm(model: QuickMotion, close: () => void): HTMLElement {
  const limits = model.limits.rawVal;
  const velocity = state(String(limits?.velocity_rpm ?? ""));
  const distance = state(String(limits?.distance_revolutions ?? ""));
  const seconds = state(String(limits?.seconds ?? ""));
  const apply = async () => {
    const values = [parsed("Velocity", velocity.rawVal), parsed("Distance", distance.rawVal), parsed("Time", seconds.rawVal)];
    const refusal = values.find((value) => typeof value === "string");
    if (typeof refusal === "string") return void (model.error.val = refusal);
    const [velocity_rpm, distance_revolutions, time] = values as number[];
    if (await model.setLimits({ velocity_rpm, distance_revolutions, seconds: time })) close();
  };
  return h("span", { class: "toolbar" },
    numberField("rpm", "limit-velocity", velocity, "80px"),
    numberField("rev", "limit-distance", distance, "80px"),
    numberField("s", "limit-seconds", seconds, "70px"),
    h("button", { class: "primary small", "data-testid": "limits-apply", onclick: () => void apply() }, "Apply"));
}
