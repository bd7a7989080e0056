/** Buses: connect by spec string, scan, add found drives to a project, NMT broadcast, close. */

import type { App, Page, PageContext } from "../app";
import { projects, type Project } from "../client/api";
import { driveApi, type BusInfo, type NodeIdentity } from "../client/drives";
import { confirmAction, failure, formDialog, messageView, toast, type Message } from "../components/ui";
import { h, state, type State } from "../lib/dom";
import { formatHex } from "../lib/numbers";
import { buildPath } from "../lib/router";

const SPEC_EXAMPLES = [
  "sim", "socketcan:can0", "pcan:PCAN_USBBUS1@1000000", "ixxat:0@500000", "kvaser:0",
  "slcan:/dev/ttyACM0@1000000", "socketcand:127.0.0.1:29536", "serial:/dev/ttyUSB0@19200",
  "profibus:/dev/ttyUSB0@1500000",
];

/** What the parts of the page share. */
interface BusView {
  app: App;
  buses: State<BusInfo[]>;
  /** Nodes found by the last scan of a bus (they replace what the server knew of it). */
  scanned: State<ReadonlyMap<string, NodeIdentity[]>>;
  scanning: State<ReadonlySet<string>>;
  message: State<Message | null>;
}

export async function busPage(context: PageContext): Promise<Page> {
  const { app } = context;
  await app.projectsReady;
  const view: BusView = {
    app, buses: state(await driveApi.buses()), scanned: state(new Map()), scanning: state(new Set()), message: state<Message | null>(null),
  };
  const spec = h("input", { type: "text", list: "bus-specs", style: { width: "300px" }, "data-testid": "bus-spec", "aria-label": "Bus spec", spellcheck: "false" });
  const busId = h("input", { type: "text", style: { width: "120px" }, "data-testid": "bus-id", "aria-label": "Bus name", placeholder: "name (optional)" });
  const connect = () => void openBus(view, spec.value.trim(), busId.value.trim());
  spec.addEventListener("keydown", (event) => event.key === "Enter" && connect());
  return {
    title: "Bus",
    focusSearch: () => { spec.focus(); return true; },
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Buses and scan")),
      h("datalist", { id: "bus-specs" }, SPEC_EXAMPLES.map((example) => h("option", { value: example }))),
      h("div", { class: "toolbar" }, h("span", null, "Bus spec"), spec, busId,
        h("button", { class: "primary", "data-testid": "bus-connect", onclick: connect }, "Connect"),
        h("span", { class: "muted" }, "e.g. sim, socketcan:can0, serial:/dev/ttyUSB0@19200")),
      projectBuses(view, (interfaceSpec, name) => {
        spec.value = interfaceSpec;
        busId.value = name;
        connect();
      }),
      messageView(view.message),
      h("div", { class: "grid", style: { gap: "12px" } }, () => view.buses.val.length
        ? view.buses.val.map((bus) => busPanel(view, bus))
        : h("div", { class: "panel empty-state" }, "No bus is open. Connect one above.")),
      h("p", { class: "muted", style: { margin: "0" } }, "Axes reach their drive through the bus of the same name; open a project's buses here, then its axes go online. ",
        h("a", { href: buildPath({ page: "terminal" }) }, "Dialog terminal"), " reads and writes any object.")),
  };
}

/** One-click buttons for the buses of the projects. */
function projectBuses(view: BusView, open: (spec: string, name: string) => void): HTMLElement | null {
  const buses = view.app.projectsLoaded().flatMap((project: Project) => project.buses.map((bus) => ({ project: project.name, bus })));
  if (buses.length === 0) return null;
  return h("div", { class: "toolbar" }, h("span", { class: "muted" }, "Buses of the projects:"),
    buses.map(({ project, bus }) => h("button", {
      class: "small", title: `Open bus ${bus.name} of project ${project} (${bus.interface})`, onclick: () => open(bus.interface, bus.name),
    }, `${project}: ${bus.name} (${bus.interface})`)));
}

/** Run an action of the page; its failure is shown above the buses. */
async function guard(view: BusView, work: () => Promise<void>): Promise<void> {
  view.message.val = null;
  try {
    await work();
  } catch (error) {
    view.message.val = failure(error, "bus-error");
  }
}

async function reload(view: BusView): Promise<void> {
  view.buses.val = await driveApi.buses();
  await view.app.refreshBuses();
}

function openBus(view: BusView, spec: string, name: string): Promise<void> {
  return guard(view, async () => {
    const bus = await driveApi.openBus(spec, name || undefined);
    toast(`Bus ${bus.id} opened (${bus.spec})`, "ok");
    await reload(view);
  });
}

function busPanel(view: BusView, bus: BusInfo): HTMLElement {
  const nodes = () => view.scanned.val.get(bus.id) ?? bus.nodes ?? [];
  const usable = () => nodes().filter((node) => node.device);
  const scanning = () => view.scanning.val.has(bus.id);
  return h("section", { class: "panel", "data-testid": `bus-${bus.id}` },
    h("h2", null, `${bus.id} · ${bus.spec}`,
      h("span", { class: "right toolbar" },
        h("span", { class: bus.connected ? "ok-text" : "error-text" }, bus.connected ? "connected" : `disconnected${bus.error ? `: ${bus.error}` : ""}`),
        h("button", { class: "small primary", "data-testid": `scan-${bus.id}`, disabled: scanning, onclick: () => void scan(view, bus) },
          () => (scanning() ? "Scanning…" : "Scan")),
        h("button", { class: "small", disabled: () => usable().length === 0, onclick: () => addToProject(view.app, bus, usable()) }, "Add all to project…"),
        h("button", { class: "small", title: "NMT start, all nodes", onclick: () => void nmt(view, bus, "start") }, "NMT start all"),
        h("button", { class: "small", title: "NMT pre-operational, all nodes", onclick: () => void nmt(view, bus, "pre-operational") }, "Pre-op all"),
        h("button", { class: "small danger", onclick: () => void close(view, bus) }, "Close"))),
    h("table", { class: "data" },
      h("thead", null, h("tr", null, ["Node", "Device name", "Dictionary", "Vendor", "Product", "Revision", "Serial", "Software", ""].map((t) => h("th", null, t)))),
      h("tbody", null, () => nodes().length
        ? nodes().map((node) => nodeRow(view, bus, node))
        : h("tr", null, h("td", { colspan: "9", class: "muted" }, "No node known yet: scan the bus.")))));
}

const hex = (value: number | null | undefined) => (value === null || value === undefined ? "" : formatHex(value, 8));

function nodeRow(view: BusView, bus: BusInfo, node: NodeIdentity): HTMLElement {
  return h("tr", { "data-testid": `scan-node-${node.node}` },
    h("td", { class: "num" }, String(node.node)),
    h("td", null, node.device_name ?? ""),
    h("td", null, node.device ?? h("span", { class: "warn-text" }, "no dictionary")),
    h("td", { class: "mono" }, hex(node.vendor_id)),
    h("td", { class: "mono" }, hex(node.product_code)),
    h("td", { class: "mono" }, hex(node.revision)),
    h("td", { class: "mono" }, node.serial_number === null || node.serial_number === undefined ? "" : String(node.serial_number)),
    h("td", null, node.software_version ?? ""),
    h("td", null, h("button", { class: "small", disabled: !node.device, "data-testid": `add-node-${node.node}`, onclick: () => addToProject(view.app, bus, [node]) }, "Add to project…")));
}

function scan(view: BusView, bus: BusInfo): Promise<void> {
  view.scanning.val = new Set([...view.scanning.rawVal, bus.id]);
  return guard(view, async () => {
    try {
      const { nodes: found, hint } = await driveApi.scan(bus.id);
      view.scanned.val = new Map([...view.scanned.rawVal, [bus.id, found]]);
      if (found.length === 0) view.message.val = { tone: "warn", text: `No node answered on ${bus.id}. ${hint ?? ""}`.trim(), testid: "scan-hint" };
      else toast(`${found.length} node${found.length === 1 ? "" : "s"} found on ${bus.id}`, "ok");
    } finally {
      view.scanning.val = new Set([...view.scanning.rawVal].filter((id) => id !== bus.id));
      view.buses.val = await driveApi.buses();
    }
  });
}

function nmt(view: BusView, bus: BusInfo, command: string): Promise<void> {
  return guard(view, async () => {
    await driveApi.nmt(bus.id, command, 0);
    toast(`NMT ${command} sent to every node of ${bus.id}`, "ok");
  });
}

async function close(view: BusView, bus: BusInfo): Promise<void> {
  if (!(await confirmAction("Close bus", `Close bus ${bus.id}? Its drives go offline in the tool (they keep running).`, "Close bus"))) return;
  await guard(view, async () => {
    await driveApi.closeBus(bus.id);
    await reload(view);
  });
}

/** Add found nodes as axes of a project (through the project's bus of that name or spec), then open the project. */
function addToProject(app: App, bus: BusInfo, nodes: NodeIdentity[]): void {
  const known = app.projectsLoaded();
  const target = h("select", { "data-testid": "add-project" }, known.map((p) => h("option", { value: p.name }, p.name)));
  const names = nodes.map((node) => h("input", { type: "text", value: `${node.device ?? "axis"}-${node.node}`.replace(/[^A-Za-z0-9_-]/g, "") }));
  formDialog({
    title: nodes.length === 1 ? `Add node ${nodes[0].node} to a project` : `Add ${nodes.length} nodes to a project`,
    body: [
      known.length ? h("label", { class: "field" }, "Project", target) : h("div", { class: "message warn" }, "Create a project first (Projects page)."),
      h("div", { class: "muted" }, `The axes use the project's bus with spec "${bus.spec}"; a project without one gets a bus "${bus.id}".`),
      h("table", { class: "data" }, h("thead", null, h("tr", null, h("th", null, "Node"), h("th", null, "Device"), h("th", null, "Axis name"))),
        h("tbody", null, nodes.map((node, i) => h("tr", null, h("td", { class: "num" }, String(node.node)), h("td", null, node.device ?? ""), h("td", null, names[i]))))),
    ],
    confirm: "Add",
    confirmTestid: "add-confirm",
    errorTestid: "dialog-error",
    disabled: known.length === 0,
    submit: async () => {
      const project = await addAxes(target.value, bus, nodes.map((node, i) => ({ node, name: names[i].value.trim() })));
      app.updateProject(project);
      toast(`${nodes.length} axis${nodes.length === 1 ? "" : "es"} added to ${project.name}`, "ok");
      app.navigate({ page: "project", project: project.name });
    },
  });
}

/** The project's own bus of that name or spec is used, else a new project bus named like the server's. */
async function addAxes(projectName: string, bus: BusInfo, axes: { node: NodeIdentity; name: string }[]): Promise<Project> {
  let project = await projects.get(projectName);
  let projectBus = project.buses.find((b) => b.name === bus.id) ?? project.buses.find((b) => b.interface === bus.spec);
  if (!projectBus) {
    projectBus = { name: bus.id, interface: bus.spec, bitrate: null };
    project = await projects.update(project.name, { buses: [...project.buses, projectBus], revision: project.revision });
  }
  for (const { node, name } of axes) {
    project = await projects.addAxis(project.name,
      { name, device: node.device ?? "", node_id: node.node, bus: projectBus.name, description: node.device_name ?? "" }, project.revision);
  }
  return project;
}
