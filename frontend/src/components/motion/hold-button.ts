/**
 * A hold-to-run button: the motion runs while it is pressed (pointer or Space/Enter) and stops when it is released
 * or the press is cancelled — the page's keepalives stop with it (`client/motion.ts`).  The button captures the
 * pointer while pressed, so a page whose layout moves under a steady finger does not end the hold; letting go
 * anywhere does.
 */

import { h, type Bindable } from "../../lib/dom";

export interface HoldButtonProps {
  label: string;
  testid: string;
  title: string;
  disabled: Bindable<boolean>;
  onPress(): void;
  onRelease(): void;
}

export function holdButton(props: HoldButtonProps): HTMLButtonElement {
  let down = false;
  const press = (event: Event) => {
    event.preventDefault();
    if (down) return;
    down = true;
    if (event instanceof PointerEvent) (event.currentTarget as HTMLElement).setPointerCapture(event.pointerId);
    props.onPress();
  };
  const release = () => {
    if (!down) return;
    down = false;
    props.onRelease();
  };
  const isKey = (event: KeyboardEvent) => event.key === " " || event.key === "Enter";
  return h("button", {
    class: "hold", "data-testid": props.testid, title: props.title, disabled: props.disabled,
    onpointerdown: press, onpointerup: release, onpointercancel: release, onlostpointercapture: release, onblur: release,
    onkeydown: (event: KeyboardEvent) => { if (isKey(event) && !event.repeat) press(event); },
    onkeyup: (event: KeyboardEvent) => { if (isKey(event)) release(); },
    oncontextmenu: (event: Event) => event.preventDefault(),
  }, props.label);
}
