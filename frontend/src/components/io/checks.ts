/**
 * What the drive acts on now (limit switches, home, INHIBIT from 0x60FD), the fail-safe check of the limit switches
 * (what is unsafe and why), and on a simulated drive the test bench inputs (0x5F00: the levels wired to it).
 */

import type { IoFinding } from "../../client/io";
import { h } from "../../lib/dom";
import type { IoPageModel } from "./model";

const ACTS_ON: [key: "negative_limit" | "positive_limit" | "home" | "inhibit", label: string][] = [
  ["negative_limit", "Negative limit"],
  ["positive_limit", "Positive limit"],
  ["home", "Home switch"],
  ["inhibit", "INHIBIT"],
];

export function actsOnView(model: IoPageModel): HTMLElement {
  return h("div", { class: "io-row", "data-testid": "io-acts-on" }, ACTS_ON.map(([key, label]) => h("span", {
    "data-testid": `io-acts-${key}`,
    class: () => `led ${(model.live.val ?? model.config.val?.state)?.[key] ? "on" : ""}`,
    title: "0x60FD: what the drive acts on now",
  }, label)));
}

export function findingsView(model: IoPageModel): HTMLElement {
  return h("div", { "data-testid": "io-findings" }, () => {
    const findings = model.config.val?.findings ?? [];
    if (!findings.length) return h("div", { class: "message ok" }, "Limit switches: nothing unsafe found.");
    return findings.map((finding) => findingLine(finding));
  });
}

function findingLine(finding: IoFinding): HTMLElement {
  const tone = finding.severity === "unsafe" ? "error" : finding.severity === "warning" ? "warn" : "ok";
  return h("div", { class: `message ${tone}`, "data-testid": `io-finding-${finding.severity}` },
    h("strong", null, `${finding.severity}: ${finding.subject}`), " — ", finding.text);
}

export function benchView(model: IoPageModel): HTMLElement {
  return h("div", null, () => {
    const bench = model.live.val?.simulated ?? model.config.val?.simulated;
    if (!bench) return null;
    return h("section", { class: "panel", "data-testid": "io-bench" },
      h("h2", null, "Simulated drive: test bench inputs (0x5F00)"),
      h("div", { class: "panel-body" },
        h("p", { class: "muted" }, bench.meaning),
        h("div", { class: "io-row" }, bench.names.map((name, bit) => h("label", null,
          h("input", {
            type: "checkbox",
            "data-testid": `io-bench-${name.split(" ")[0]}`,
            checked: () => Boolean((model.live.val?.simulated?.value ?? bench.value) >> bit & 1),
            disabled: () => model.busy.val,
            onchange: () => void model.setSimInputs((model.live.rawVal?.simulated?.value ?? bench.value) ^ (1 << bit)),
          }), ` ${name}`)))));
  });
}
