/**
 * The live monitor (docs/sequences.md, Live monitor): the running sequence and phase, the outputs, the loop counter,
 * the captured position, and the timeline — one entry per executed sequence with when it began and the last phase
 * it reached, and a strip of every phase change on the time axis.
 */

import type { MonitorSnapshot } from "../../client/sequences";
import { h, type State } from "../../lib/dom";

const PALETTE = ["#2b6cb0", "#2f855a", "#b7791f", "#6b46c1", "#c53030", "#2c7a7b", "#97266d", "#4a5568"];
const bitsText = (value: number, width: number) => value.toString(2).padStart(width, "0");

export function monitorView(monitor: State<MonitorSnapshot | null>): HTMLElement {
  return h("div", { "data-testid": "sequence-monitor" }, () => {
    const now = monitor.val;
    if (!now) return h("p", { class: "muted" }, "Monitor off: Start or Monitor turns it on.");
    return [
      h("table", { class: "kv" }, h("tbody", null,
        row("Running", now.running ? `sequence ${now.sequence}` : "no program", "monitor-sequence"),
        row("Phase", now.phase, "monitor-phase"),
        row("Outputs 0x3602,1", bitsText(now.outputs, 8), "monitor-outputs"),
        row("POS SEQ SPEED READY", bitsText(now.dedicated_outputs, 4).split("").reverse().join(" "), "monitor-dedicated"),
        row("Loop counter", now.counter ? `sequence ${now.counter.sequence}: ${now.counter.remaining} to go` : "—", "monitor-counter"),
        row("Captured position 0x360B", now.captured_position ?? "—", "monitor-captured"))),
      strip(now),
      h("ol", { "data-testid": "sequence-timeline" }, now.executed.map((entry) =>
        h("li", { "data-testid": "timeline-entry", "data-sequence": String(entry.sequence) }, `${entry.t.toFixed(3)} s — sequence ${entry.sequence} (${entry.phase})`))),
    ];
  });
}

function row(label: string, value: string | number, testid: string): HTMLElement {
  return h("tr", null, h("td", null, label), h("td", { "data-testid": testid }, String(value)));
}

/** Every sample on the time axis: a block per sequence, the phase named above it. */
function strip(now: MonitorSnapshot): Element {
  const samples = now.timeline;
  const width = 600;
  const start = samples.find((sample) => sample.sequence >= 0)?.t ?? samples[0]?.t ?? 0; // from the first sequence
  const span = Math.max((samples[samples.length - 1]?.t ?? 0) - start, 1e-3);
  const x = (t: number) => 10 + ((t - start) / span) * (width - 20);
  const NS = "http://www.w3.org/2000/svg";
  const root = document.createElementNS(NS, "svg");
  root.setAttribute("viewBox", `0 0 ${width} 46`);
  root.setAttribute("width", "100%");
  root.setAttribute("preserveAspectRatio", "none");
  root.setAttribute("data-testid", "timeline-strip");
  samples.forEach((sample, index) => {
    if (sample.sequence < 0) return;
    const end = samples[index + 1]?.t ?? sample.t;
    const block = document.createElementNS(NS, "rect");
    const attributes = { x: x(sample.t), y: 18, width: Math.max(x(end) - x(sample.t), 1), height: 20, fill: PALETTE[sample.sequence % PALETTE.length] };
    for (const [key, value] of Object.entries(attributes)) block.setAttribute(key, String(value));
    const title = document.createElementNS(NS, "title");
    title.textContent = `${sample.t.toFixed(3)} s: sequence ${sample.sequence} ${sample.phase}`;
    block.append(title);
    root.append(block);
  });
  return root;
}
