/**
 * The chaining graph the server computed from the editor's file (docs/sequences.md, Chaining graph), drawn as SVG:
 * the sequences in number order on a grid, an arrow per edge coloured by its kind (next, counter, condition; a link
 * no rule takes dashed), a dangling edge to a red "?"; unreachable sequences dashed, unsupported types red. The
 * findings are listed under it.
 */

import type { GraphEdge, SequenceGraph } from "../../client/sequences";
import { h } from "../../lib/dom";
import type { SequenceModel } from "./model";

const SVG = "http://www.w3.org/2000/svg";
const STEP_X = 110;
const STEP_Y = 80;
const RADIUS = 22;
export const EDGE_COLOURS: Record<string, string> = { next: "#2b6cb0", counter: "#b7791f", condition: "#6b46c1", link: "#a0aec0" };

type Point = { x: number; y: number };

function svg(tag: string, attributes: Record<string, string | number>, ...children: (Node | string)[]): SVGElement {
  const element = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) element.setAttribute(key, String(value));
  element.append(...children);
  return element;
}

/** Grid positions: as many columns as the square root of the count, in number order. */
export function layout(numbers: number[]): Map<number, Point> {
  const columns = Math.max(1, Math.ceil(Math.sqrt(numbers.length)));
  return new Map(numbers.map((number, index) => [number, { x: 50 + (index % columns) * STEP_X, y: 40 + Math.floor(index / columns) * STEP_Y }]));
}

export function graphView(model: SequenceModel): HTMLElement {
  return h("div", { "data-testid": "sequence-graph" }, () => {
    const graph = model.check.val?.graph;
    if (!graph) return h("p", { class: "muted" }, model.check.val ? "The file has errors: no graph until they are fixed." : "…");
    return [drawing(graph), findings(graph)];
  });
}

function drawing(graph: SequenceGraph): Element {
  const places = layout(graph.nodes.map((node) => node.sequence));
  const width = Math.max(...[...places.values()].map((p) => p.x), 0) + 90;
  const height = Math.max(...[...places.values()].map((p) => p.y), 0) + 70;
  const arrows = Object.entries(EDGE_COLOURS).map(([kind, colour]) => svg("marker", {
    id: `arrow-${kind}`, viewBox: "0 0 10 10", refX: 10, refY: 5, markerWidth: 7, markerHeight: 7, orient: "auto-start-reverse",
  }, svg("path", { d: "M 0 0 L 10 5 L 0 10 z", fill: colour })));
  return svg("svg", { width, height, viewBox: `0 0 ${width} ${height}`, role: "img", "aria-label": "chaining graph" },
    svg("defs", {}, ...arrows),
    ...graph.edges.map((edge) => edgePath(edge, places)),
    ...graph.nodes.map((node) => {
      const at = places.get(node.sequence)!;
      const stroke = node.supported ? "#2d3748" : "#c53030";
      return svg("g", { "data-testid": `graph-node-${node.sequence}`, "data-type": node.type },
        svg("circle", { cx: at.x, cy: at.y, r: RADIUS, fill: node.entry ? "#ebf8ff" : "#fff", stroke, "stroke-width": 2, "stroke-dasharray": node.reachable ? "" : "4 3" }),
        svg("text", { x: at.x, y: at.y - 2, "text-anchor": "middle", "font-size": 13, "font-weight": "bold" }, String(node.sequence)),
        svg("text", { x: at.x, y: at.y + 12, "text-anchor": "middle", "font-size": 9 }, node.type));
    }));
}

function edgePath(edge: GraphEdge, places: Map<number, Point>): Element {
  const from = places.get(edge.from)!;
  const colour = EDGE_COLOURS[edge.kind] ?? "#000";
  const common = { stroke: colour, fill: "none", "stroke-width": 1.6, "marker-end": `url(#arrow-${edge.kind})`, "data-testid": `graph-edge-${edge.from}-${edge.to}-${edge.kind}`, "stroke-dasharray": edge.kind === "link" ? "5 4" : "" };
  const to = places.get(edge.to);
  if (!to) {
    const end = { x: from.x + 45, y: from.y - 30 };
    return svg("g", {}, svg("path", { ...common, d: `M ${from.x + RADIUS * 0.7} ${from.y - RADIUS * 0.7} L ${end.x} ${end.y}` }),
      svg("text", { x: end.x + 4, y: end.y - 2, fill: "#c53030", "font-size": 12 }, `${edge.to}?`));
  }
  if (edge.from === edge.to) {
    return svg("path", { ...common, d: `M ${from.x - 8} ${from.y - RADIUS} C ${from.x - 30} ${from.y - 60}, ${from.x + 30} ${from.y - 60}, ${from.x + 8} ${from.y - RADIUS}` });
  }
  const [a, b] = [trim(from, to), trim(to, from)];
  const bend = edge.kind === "next" ? 0.15 : -0.3; // the back edges of loops curve the other way
  const mid = { x: (a.x + b.x) / 2 - (b.y - a.y) * bend, y: (a.y + b.y) / 2 + (b.x - a.x) * bend };
  return svg("path", { ...common, d: `M ${a.x} ${a.y} Q ${mid.x} ${mid.y} ${b.x} ${b.y}` });
}

/** The point where the line from `from` to `to` leaves the circle around `from`. */
function trim(from: Point, to: Point): Point {
  const length = Math.hypot(to.x - from.x, to.y - from.y) || 1;
  return { x: from.x + ((to.x - from.x) / length) * RADIUS, y: from.y + ((to.y - from.y) / length) * RADIUS };
}

function findings(graph: SequenceGraph): HTMLElement {
  if (!graph.findings.length) return h("div", { class: "message ok", "data-testid": "graph-findings" }, "No findings: every loop has an exit, every link a target.");
  return h("div", { "data-testid": "graph-findings" }, graph.findings.map((finding) =>
    h("div", { class: "message warn", "data-testid": `finding-${finding.kind}` }, finding.message)));
}
