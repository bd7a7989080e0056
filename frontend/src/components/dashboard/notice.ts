/** The dashboard's message line: a command's refusal, the live data's error, or "drive not reachable" with Open bus. */

import { h, type State } from "../../lib/dom";

export type DashboardMessage =
  | { kind: "error"; text: string; testid?: string }
  | { kind: "offline"; text: string; bus: { name: string; interface: string } | null };

export interface NoticeProps {
  message: State<DashboardMessage | null>;
  onOpenBus(bus: { name: string; interface: string }): void;
}

export function dashboardNotice(props: NoticeProps): HTMLElement {
  return h("div", null, () => {
    const message = props.message.val;
    if (!message) return null;
    if (message.kind === "error") return h("div", { class: "message error", "data-testid": message.testid ?? false }, message.text);
    const bus = message.bus;
    return h("div", { class: "message warn toolbar", "data-testid": "dashboard-offline" }, message.text,
      bus ? h("button", { class: "small primary", onclick: () => props.onOpenBus(bus) }, `Open bus ${bus.name} (${bus.interface})`) : null);
  });
}
