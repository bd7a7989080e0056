/** The status word decoded bit by bit from the dictionary's bit fields. */

import { extractBits, fieldLabel } from "../../lib/bits";
import { derive, h, untrack, type State } from "../../lib/dom";
import type { Entry } from "../../lib/od";

export interface StatusWordProps {
  /** 0x6041 when the dictionary has it. */
  entry: Entry | null;
  address: string;
  statusword: State<number | null>;
}

export function statusWordPanel(props: StatusWordProps): HTMLElement {
  const known = derive(() => props.statusword.val !== null);
  return h("section", { class: "panel" },
    h("h2", null, "Status word", h("span", { class: "right mono" }, props.entry ? props.address : "")),
    h("div", { class: "panel-body" }, h("div", { class: "sw-bits", "data-testid": "dashboard-sw-bits" },
      () => (known.val && props.entry ? untrack(() => bitRows(props.entry!, props.statusword)) : null))));
}

function bitRows(entry: Entry, statusword: State<number | null>): HTMLElement[] {
  return entry.variable.bits.flatMap((field) => {
    const set = () => extractBits(statusword.val ?? 0, field.first, field.last) !== 0;
    return [
      h("div", { class: () => `bitno ${set() ? "set" : ""}` }, fieldLabel(field)),
      h("div", { class: () => (set() ? "set" : "muted"), title: field.name }, () => `${set() ? "● " : "○ "}${field.name}`),
    ];
  });
}
