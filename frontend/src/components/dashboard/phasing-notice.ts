/**
 * The dashboard's notice for warning bit 30 "Motor phasing init not OK" (an incremental encoder without Hall sensors
 * after a 24 V power-up, or after an encoder fault): until motor phasing ran the drive refuses Enable operation.
 * One click runs it ('mcal' as a server job) when this page armed the axis; the phasing page has the checklist.
 */

import type { FaultReport } from "../../client/drives";
import { runJob } from "../../client/jobs";
import type { LiveHub } from "../../client/live";
import { proceduresApi, type ProceduresClient } from "../../client/procedures";
import { h, state, valueOf, type Bindable, type State } from "../../lib/dom";
import { needsMotorPhasing } from "../../lib/procedures";
import { errorText, type Message } from "../ui";

export interface PhasingNoticeProps {
  live: LiveHub;
  where: { bus: string; node: number; project: string; axis: string };
  faults: State<FaultReport | string | null>;
  /** This page armed the axis: motor phasing turns the motor. */
  armed: Bindable<boolean>;
  phasingHref: string;
  client?: ProceduresClient;
}

export function phasingNotice(props: PhasingNoticeProps): HTMLElement {
  const running = state(false);
  const message = state<Message | null>(null);
  const needed = () => {
    const report = props.faults.val;
    return report !== null && typeof report !== "string" && needsMotorPhasing(report.warnings);
  };
  const blocked = () => (running.val ? "Motor phasing is running…" : valueOf(props.armed) ? "" : "Arm the axis first (Controller): motor phasing turns the motor");
  const remedy = async () => {
    running.val = true;
    message.val = null;
    message.val = await runMotorPhasing(props).finally(() => (running.val = false));
  };
  return h("div", null, () => (needed() ? h("div", { class: "message warn toolbar", "data-testid": "phasing-warning" },
    h("span", null, "Warning bit 30 — motor phasing init not OK: the drive refuses Enable operation until motor phasing ran ",
      "(incremental encoder without Hall sensors: after every 24 V power-up). It turns the motor up to one electrical revolution."),
    h("button", { class: "small primary", "data-testid": "phasing-remedy", disabled: () => blocked() !== "", title: blocked, onclick: () => void remedy() },
      () => (running.val ? "Motor phasing…" : "Run motor phasing")),
    h("a", { href: props.phasingHref }, "Phasing page")) : null),
  () => {
    const current = message.val;
    return current ? h("div", { class: `message ${current.tone}`, "data-testid": current.testid }, current.text) : null;
  });
}

/** Run 'mcal' as a job and say how it ended. */
export async function runMotorPhasing(props: PhasingNoticeProps): Promise<Message> {
  const client = props.client ?? proceduresApi;
  const { bus, node, project, axis } = props.where;
  try {
    const job = await runJob(props.live, () => client.start(bus, node, "motor_phasing", { options: {}, verify: false, project, axis }), () => undefined);
    if (job.state === "failed") return { text: `Motor phasing: ${job.error ?? "failed"}`, tone: "error", testid: "phasing-remedy-failed" };
    if (job.state === "cancelled") return { text: "Motor phasing aborted.", tone: "warn", testid: "phasing-remedy-failed" };
    return { text: "Motor phasing done: the drive can be enabled.", tone: "ok", testid: "phasing-remedy-done" };
  } catch (error) {
    return { text: `Motor phasing: ${errorText(error)}`, tone: "error", testid: "phasing-remedy-failed" };
  }
}
