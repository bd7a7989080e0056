/**
 * One procedure's panel: what it does, its options, the manual's safety checklist the user ticks, the drive's
 * preconditions with their reasons, Start (disabled with the reason until everything is met and, for a procedure
 * that turns the motor, the axis is armed by this page), Abort, the live progress and the result.
 */

import type { ProcedureProgress, ProcedureResult, StartRequest } from "../../client/procedures";
import { h, state, type Child, type State } from "../../lib/dom";
import { CHECKLISTS, startBlock } from "../../lib/procedures";
import { errorText, messageView } from "../ui";
import { abort, armed, infoOf, run, start, type ProceduresModel } from "./model";

export interface RunnerProps {
  model: ProceduresModel;
  name: string;
  title: string;
  intro: Child;
  /** The options form, if any. */
  fields?: Child;
  /** The options of the request, read when Start is clicked; throws (with the reason) on bad input. */
  options?: () => StartRequest["options"];
  /** Preconditions (`value:<object>`) the options provide: the server writes them first. */
  provides?: () => string[];
  /** Run the verification after the procedure (default: yes). */
  verify?: State<boolean>;
  startLabel?: string;
  result(result: ProcedureResult): Child;
}

const STATUS_TEXT: Record<string, string> = {
  never: "never executed", cannot: "cannot execute", running: "running", aborted: "aborted by the user",
  error: "stopped on error", done: "performed", unknown: "unknown",
};

export function runnerPanel(props: RunnerProps): HTMLElement {
  const { model, name } = props;
  const current = run(model, name);
  const items = CHECKLISTS[name] ?? [];
  const ticks = state(items.map(() => false));
  const provided = () => props.provides?.() ?? [];
  const block = () => startBlock(infoOf(model, name), armed(model), items.filter((_, i) => !ticks.val[i]), current.job.val !== null, provided());
  const onStart = () => {
    let options: StartRequest["options"];
    try {
      options = props.options ? props.options() : {};
    } catch (error) {
      current.message.val = { text: errorText(error), tone: "error", testid: `${name}-invalid` };
      return;
    }
    void start(model, name, options, props.verify?.rawVal ?? true);
  };
  return h("section", { class: "panel", "data-testid": `proc-${name}` },
    h("h2", null, props.title, h("span", { class: "right muted", "data-testid": `${name}-status` }, () => {
      const info = infoOf(model, name);
      return info ? `drive: ${STATUS_TEXT[info.status] ?? info.status}` : "";
    })),
    h("div", { class: "panel-body grid", style: { gap: "10px" } },
      h("div", { class: "muted" }, props.intro),
      props.fields ?? null,
      items.length ? checklist(name, items, ticks) : null,
      preconditions(model, name, provided),
      h("div", { class: "toolbar" },
        h("button", { class: "primary", "data-testid": `${name}-start`, disabled: () => block() !== null, title: () => block() ?? "", onclick: onStart },
          props.startLabel ?? "Start"),
        h("button", { class: "danger", "data-testid": `${name}-abort`, disabled: () => current.job.val === null,
          title: "Write 0 to the trigger: the drive is left disabled, the gains as before", onclick: () => void abort(model, name) }, "Abort"),
        h("span", { class: "muted", "data-testid": `${name}-reason` }, () => (current.job.val === null ? block() ?? "Ready." : ""))),
      h("div", { "data-testid": `${name}-progress` }, () => (current.job.val !== null ? progressView(current.progress.val) : null)),
      messageView(current.message),
      h("div", { "data-testid": `${name}-result` }, () => {
        const result = current.result.val;
        return result ? props.result(result) : null;
      })));
}

function checklist(name: string, items: string[], ticks: State<boolean[]>): HTMLElement {
  const tick = (position: number, on: boolean) => (ticks.val = ticks.rawVal.map((value, i) => (i === position ? on : value)));
  return h("fieldset", { class: "checklist", "data-testid": `${name}-checklist` },
    h("legend", null, "Safety checklist (manual): tick each before Start"),
    items.map((text, position) => h("label", { class: "check", style: { display: "block" } },
      h("input", { type: "checkbox", "data-testid": `${name}-check-${position}`, checked: () => ticks.val[position],
        onchange: (event: Event) => tick(position, (event.target as HTMLInputElement).checked) }),
      ` ${text}`)));
}

function preconditions(model: ProceduresModel, name: string, provided: () => string[]): HTMLElement {
  return h("div", null, h("strong", null, "Preconditions read from the drive"),
    h("ul", { class: "preconditions", "data-testid": `${name}-preconditions` }, () => {
      const info = infoOf(model, name);
      if (model.listError.val) return h("li", { class: "error-text" }, model.listError.val);
      if (!info) return h("li", { class: "muted" }, model.procedures.val === null ? "Reading…" : "The drive does not offer this procedure.");
      if (info.preconditions.length === 0) return h("li", { class: "muted" }, "none");
      const given = provided();
      return info.preconditions.map((condition) => {
        const ok = condition.ok || given.includes(condition.name);
        const why = condition.ok ? "" : ok ? " — given above, written first" : condition.reason ? `: ${condition.reason}` : "";
        return h("li", { class: ok ? "ok-text" : "error-text", "data-testid": `${name}-pre-${condition.name}`, "data-ok": String(ok) },
          `${ok ? "✓" : "✗"} ${condition.label}${why}`);
      });
    }));
}

export function progressView(progress: ProcedureProgress | null): HTMLElement {
  if (!progress) return h("div", { class: "muted" }, "Starting…");
  return h("div", { class: "progress-line" },
    h("strong", { "data-testid": "procedure-phase" }, progress.phase),
    h("progress", progress.fraction === null ? {} : { max: 1, value: progress.fraction }),
    h("span", { class: "muted", style: { whiteSpace: "nowrap" } }, `${progress.elapsed_s.toFixed(1)} s`),
    h("span", { "data-testid": "procedure-message" }, progress.message));
}
