/**
 * Quick test (manual §1.8.19): profile velocity by its objects — acceleration, deceleration and target velocity in
 * their units; Set mode and run checks all three and hands them on, Stop writes target 0 (when the device has a
 * profile velocity mode) — and, with `motion`, the hold-to-run motions behind the arm switch: jog, moves, homing
 * (`components/motion/`), also on a device without CiA 402 modes (the TTA-PRO: through its control word).
 */

import { motionPanel, type MotionPanelProps } from "../motion/motion-panel";
import { numberEditor, type ValueEditor } from "../editors";
import { h, type Bindable } from "../../lib/dom";
import type { Entry, Scalar } from "../../lib/od";

export interface QuickTestValue {
  entry: Entry;
  raw: number | string;
  /** As typed (for the confirmation). */
  text: string;
}

export interface QuickTestProps {
  acceleration: Entry | null;
  deceleration: Entry | null;
  /** The target velocity; null: the device has no profile velocity mode (the TTA-PRO), only the motions. */
  target: Entry | null;
  /** The drive's value of a field's entry (shown until the user types). */
  value(entry: Entry): Bindable<Scalar>;
  onRun(values: QuickTestValue[]): void;
  /** Write target 0; true when written (the target field then shows the drive's value again). */
  onStop(): Promise<boolean>;
  /** A field's text was refused: `<name>: <reason>`. */
  onRefuse(message: string): void;
  /** The hold-to-run jog, moves and homing of the axis. */
  motion?: MotionPanelProps;
}

interface Field {
  entry: Entry;
  label: string;
  editor: ValueEditor;
}

export function quickTest(props: QuickTestProps): HTMLElement {
  return h("section", { class: "panel" },
    h("h2", null, props.motion ? "Quick test" : "Quick test · profile velocity"),
    h("div", { class: "panel-body grid", style: { gap: "8px" } },
      props.target ? profileVelocity(props, props.target) : null,
      props.motion ? motionPanel(props.motion) : null));
}

/** The profile velocity fields with Set mode and run / Stop. */
function profileVelocity(props: QuickTestProps, targetEntry: Entry): HTMLElement[] {
  const field = (entry: Entry | null, label: string, testid: string): Field | null => entry && {
    entry, label,
    editor: numberEditor(entry.variable, {
      value: props.value(entry),
      attrs: { style: { width: "110px" }, "data-testid": testid, "aria-label": label },
    }),
  };
  const target = field(targetEntry, "Target velocity", "qt-velocity")!;
  const fields = [field(props.acceleration, "Acceleration", "qt-acceleration"), field(props.deceleration, "Deceleration", "qt-deceleration"), target]
    .filter((candidate): candidate is Field => candidate !== null);
  const run = () => {
    const values: QuickTestValue[] = [];
    for (const { entry, editor } of fields) {
      const parsed = editor.submit();
      if (!parsed.ok) return props.onRefuse(`${entry.variable.name}: ${parsed.error}`);
      values.push({ entry, raw: parsed.raw, text: editor.text.rawVal });
    }
    props.onRun(values);
  };
  const stop = async () => {
    if (await props.onStop()) target.editor.revert();
  };
  return [
    h("div", { class: "toolbar" }, fields.map(({ entry, label, editor }) =>
      h("label", { class: "field" }, `${label} [${entry.variable.unit}]`, editor.element))),
    h("div", { class: "toolbar" },
      h("button", { class: "primary", "data-testid": "qt-run", onclick: run }, "Set mode and run"),
      h("button", { "data-testid": "qt-stop", onclick: () => void stop() }, "Stop (target 0)"),
      h("span", { class: "muted" }, "Runs only while the drive is in Operation enabled.")),
  ];
}
