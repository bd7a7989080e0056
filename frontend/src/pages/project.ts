/** One project: its buses and axes (add, edit, remove), archive download, DCF export and import, commission, compare, kept revisions. */

import type { App, Page, PageContext } from "../app";
import { listDictionaries, projectAddress, projects, type AxisConfig, type BusConfig, type DcfImport, type Project } from "../client/api";
import { busMatches, driveApi, serverBus, type BusInfo, type BusMatch } from "../client/drives";
import { axisStateText } from "../client/live";
import { commissionPanel } from "../components/commissionjob";
import { confirmChanges } from "../components/confirm/changes";
import { axisDialog, busesDialog, renameDialog } from "../components/project-dialogs";
import { revisionsPanel } from "../components/project-revisions";
import { reportButton } from "../components/report/button";
import { confirmAction, download, failure, messageView, pickFile, toast, type Message } from "../components/ui";
import { h, Scope, state, type State } from "../lib/dom";
import type { DictionarySummary, Scalar } from "../lib/od";
import { buildPath } from "../lib/router";

/** What the parts of the page share: the project as the server last answered it, and the server's buses. */
interface ProjectView {
  app: App;
  project: State<Project>;
  devices: DictionarySummary[];
  serverBuses: State<BusInfo[]>;
  message: State<Message | null>;
  dcfImport: State<DcfResult | null>;
}

/** The last DCF import: which axis, from which file, and what it set and left out. */
interface DcfResult {
  axis: string;
  file: string;
  result: DcfImport;
}

export async function projectPage(context: PageContext, name: string): Promise<Page> {
  const { app } = context;
  const [project, devices, buses] = await Promise.all([projects.get(name), listDictionaries(), driveApi.buses().catch(() => [])]);
  const view: ProjectView = { app, project: state(project), devices, serverBuses: state(buses), message: state<Message | null>(null),
    dcfImport: state<DcfResult | null>(null) };
  // Rows follow the live hub and the bus mapping, which outlive the page: the page's scope stops those bindings.
  const scope = new Scope();
  return {
    title: project.name,
    crumbs: [h("a", { href: "/" }, "Projects"), ` / ${project.name}`],
    dispose: () => scope.dispose(),
    element: scope.run(() => h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", { "data-testid": "project-title" }, project.name),
        h("span", { class: "muted" }, () => view.project.val.description)),
      projectToolbar(view),
      messageView(view.message),
      dcfImportResult(view),
      h("div", { class: "panel" }, h("h2", null, "Axes"), axesTable(view)),
      commissionPanel(app, project.name, () => void projects.get(project.name).then((next) => changed(view, next))),
      h("div", { class: "panel" }, h("h2", null, "Buses"), busesTable(view)),
      revisionsPanel(view.project, (next) => changed(view, next)))),
  };
}

/** A new state of the project from the server: shown here and in the tree. */
function changed(view: ProjectView, next: Project): void {
  view.project.val = next;
  view.app.updateProject(next);
}

/** Run an action of the page; its failure is shown under the toolbar. */
async function guard(view: ProjectView, work: () => Promise<void>): Promise<void> {
  try {
    view.message.val = null;
    await work();
  } catch (error) {
    view.message.val = failure(error, "page-message");
  }
}

function projectToolbar(view: ProjectView): HTMLElement {
  const { app } = view;
  const project = () => view.project.rawVal;
  const onChange = (next: Project) => changed(view, next);
  return h("div", { class: "toolbar" },
    h("button", { class: "primary", "data-testid": "add-axis", onclick: () => axisDialog(project(), view.devices, null, onChange),
      disabled: () => view.project.val.buses.length === 0 }, "Add axis…"),
    h("a", { class: "button", href: buildPath({ page: "compare", project: project().name }) }, "Compare"),
    h("button", { onclick: () => busesDialog(project(), onChange) }, "Buses…"),
    h("button", { "data-testid": "archive", onclick: () => download(projects.archiveUrl(project().name)), title: "Download the project as one .zip file" }, "Archive"),
    reportButton(project().name),
    h("button", { onclick: () => renameDialog(app, project(), false) }, "Rename…"),
    h("button", { onclick: () => renameDialog(app, project(), true) }, "Duplicate…"),
    h("button", { class: "danger", onclick: () => void deleteProject(view) }, "Delete…"));
}

async function deleteProject(view: ProjectView): Promise<void> {
  const project = view.project.rawVal;
  if (!(await confirmAction("Delete project", `Delete project ${project.name} with all its axis files? Archive it first if you may need it again.`, "Delete", true))) return;
  await guard(view, async () => {
    await projects.remove(project.name, project.revision);
    toast(`Project ${project.name} deleted`, "ok");
    await view.app.refreshProjects();
    view.app.navigate({ page: "home" });
  });
}

function axesTable(view: ProjectView): HTMLElement {
  return h("table", { class: "data", "data-testid": "axes-table" },
    h("thead", null, h("tr", null, ["Axis", "Device", "Node", "Bus", "State", "Motor", "Description", ""].map((t) => h("th", null, t)))),
    h("tbody", null, () => {
      const project = view.project.val;
      if (project.axes.length === 0) return h("tr", null, h("td", { colspan: "8", class: "muted" }, "No axis yet: add one per drive (device, node ID, bus)."));
      return project.axes.map((axis) => axisRow(view, project, axis));
    }));
}

function axisRow(view: ProjectView, project: Project, axis: AxisConfig): HTMLElement {
  const status = view.app.live.axisState(axis.bus, axis.node_id);
  const link = (target: "dashboard" | "parameters" | "commissioning", label: string) =>
    h("a", { href: buildPath({ page: "axis", project: project.name, axis: axis.name, view: target }) }, label);
  const deviceName = view.devices.find((d) => d.device === axis.device)?.product_name ?? axis.device;
  return h("tr", { "data-testid": `axis-row-${axis.name}` },
    h("td", null, link("dashboard", axis.name)),
    h("td", null, deviceName),
    h("td", { class: "num" }, String(axis.node_id)),
    h("td", null, axis.bus),
    h("td", null, () => {
      const text = axisStateText(status.val);
      return [h("span", { class: `dot ${text.tone}` }), " ", text.text];
    }),
    h("td", null, axis.motor || h("span", { class: "muted" }, "none")),
    h("td", { class: "wrap" }, axis.description),
    h("td", null, h("span", { class: "toolbar" }, link("parameters", "Parameters"), link("commissioning", "Checklist"),
      h("button", { class: "small", onclick: () => download(projects.dcfUrl(project.name, axis.name)), title: "Export the project values as a CiA 306 DCF" }, "DCF"),
      h("button", { class: "small", "data-testid": `import-dcf-${axis.name}`, onclick: () => void importDcf(view, axis), title: "Set the axis's project values to what a CiA 306 DCF configures" }, "Import DCF…"),
      h("button", { class: "small", onclick: () => axisDialog(project, view.devices, axis, (next) => changed(view, next)) }, "Edit"),
      h("button", { class: "small danger", onclick: () => void removeAxis(view, axis) }, "Remove"))));
}

/** Pick a DCF and set the axis's project values to what it configures: the server checks it all first (a dry
 * run), the user confirms the list of changes (old → new), then it is imported at the revision that was shown. */
async function importDcf(view: ProjectView, axis: AxisConfig): Promise<void> {
  const file = await pickFile(".dcf,.DCF,.eds,.EDS");
  if (!file) return;
  await guard(view, async () => {
    view.dcfImport.val = null;
    const project = view.project.rawVal;
    const preview = await projects.importDcf(project.name, axis.name, file, project.revision, true);
    if (!(await confirmDcfImport(axis, file, preview))) return;
    const result = await projects.importDcf(project.name, axis.name, file, preview.revision);
    view.dcfImport.val = { axis: axis.name, file: file.name, result };
    changed(view, await projects.get(project.name));
  });
}

function confirmDcfImport(axis: AxisConfig, file: File, preview: DcfImport): Promise<boolean> {
  const value = (raw: Scalar, unit: string) => (raw === null ? "—" : `${raw} ${unit}`.trim());
  const count = preview.changes.length;
  return confirmChanges({
    title: "Import DCF",
    text: `${count} project value${count === 1 ? "" : "s"} of axis ${axis.name} change to what ${file.name} configures (project → DCF).`,
    changes: preview.changes.map((change) => ({ address: projectAddress(change.index, change.subindex), name: change.name,
      old: value(change.old, change.unit), new: value(change.new, change.unit) })),
    notes: [
      ...(preview.skipped.length ? [`${preview.skipped.length} configured value${preview.skipped.length === 1 ? "" : "s"} the project cannot hold will be left out (listed after the import).`] : []),
      "The project as it is now is kept as a revision: you can restore it below.",
    ],
    confirm: "Import",
    folded: count > 20,
  });
}

/** What the last DCF import set, and every configured value it left out with its reason. */
function dcfImportResult(view: ProjectView): HTMLElement {
  return h("div", null, () => {
    const last = view.dcfImport.val;
    if (!last) return null;
    const { parameters, skipped } = last.result;
    const left = skipped.length ? ` ${skipped.length} configured value${skipped.length === 1 ? "" : "s"} left out:` : "";
    return h("div", { class: `message ${skipped.length ? "warn" : "ok"}`, "data-testid": "dcf-result" },
      `Axis ${last.axis}: ${parameters.length} project value${parameters.length === 1 ? "" : "s"} set from ${last.file}.${left}`,
      skipped.length ? h("ul", { "data-testid": "dcf-skipped" }, skipped.map((reason) => h("li", null, reason))) : null);
  });
}

async function removeAxis(view: ProjectView, axis: AxisConfig): Promise<void> {
  const project = view.project.rawVal;
  if (!(await confirmAction("Remove axis", `Remove axis ${axis.name} and its parameter files from project ${project.name}?`, "Remove", true))) return;
  await guard(view, async () => changed(view, await projects.removeAxis(project.name, axis.name, project.revision)));
}

function busesTable(view: ProjectView): HTMLElement {
  return h("table", { class: "data" },
    h("thead", null, h("tr", null, h("th", null, "Name"), h("th", null, "Spec"), h("th", { class: "num" }, "Bit rate"), h("th", null, "Server"))),
    h("tbody", null, () => {
      const project = view.project.val;
      if (project.buses.length === 0) return h("tr", null, h("td", { colspan: "4", class: "muted" }, "No bus: add one before adding axes."));
      return project.buses.map((bus) => h("tr", null,
        h("td", null, bus.name), h("td", { class: "mono" }, bus.interface), h("td", { class: "num" }, bus.bitrate ? `${bus.bitrate / 1000} kbit/s` : ""),
        h("td", null, () => serverCell(view, bus))));
    }));
}

/** The server bus a project bus maps to, or Connect when the server has not opened it. */
function serverCell(view: ProjectView, bus: BusConfig): Node {
  const open = view.serverBuses.val.find((candidate) => candidate.id === serverBus(bus.name));
  if (open) {
    return h("span", { class: "toolbar" },
      h("span", { class: open.connected ? "ok-text" : "error-text" }, `${open.connected ? "connected" : "disconnected"} as ${open.id}`),
      busMatchNote(busMatches.val.get(bus.name), open));
  }
  return h("span", { class: "toolbar" }, h("span", { class: "muted" }, "not open"),
    h("button", { class: "small primary", "data-testid": `open-bus-${bus.name}`, onclick: () => void openBus(view, bus) }, "Connect"));
}

/** How the server matched the project bus to its open bus, when not simply by the same name and spec. */
function busMatchNote(match: BusMatch | undefined, open: BusInfo): Node | null {
  if (match?.by === "spec") return h("span", { class: "muted", "data-testid": "bus-match-note" }, `same spec, opened on the server as ${open.id}`);
  if (match?.by === "name_only") return h("span", { class: "warn-text", "data-testid": "bus-match-note" }, `the server's ${open.id} has another spec: ${open.spec}`);
  return null;
}

async function openBus(view: ProjectView, bus: BusConfig): Promise<void> {
  await guard(view, async () => {
    await driveApi.openBus(bus.interface, bus.name);
    await view.app.refreshBuses();
    view.serverBuses.val = await driveApi.buses().catch(() => []);
    await view.app.live.refreshAxes();
  });
}
