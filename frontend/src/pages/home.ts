/** Projects: list, create, open, import an archive. */

import type { App, Page, PageContext } from "../app";
import { ApiError, listDictionaries, projects, type Project, type ProjectSummary } from "../client/api";
import { errorText, formDialog, pickFile, toast } from "../components/ui";
import { h } from "../lib/dom";
import type { DictionarySummary } from "../lib/od";
import { buildPath } from "../lib/router";

export async function homePage(context: PageContext): Promise<Page> {
  const { app } = context;
  const [list, devices] = await Promise.all([projects.list(), listDictionaries().catch(() => [])]);
  return {
    title: "Servo Studio",
    crumbs: ["Projects"],
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Projects"),
        h("button", { class: "primary", "data-testid": "new-project", onclick: () => newProjectDialog(app) }, "New project…"),
        h("button", { onclick: () => void importArchive(app), "data-testid": "unarchive", title: "Import a project archive (.zip) made with Archive" }, "Import archive…")),
      projectTable(list),
      supportedDevices(devices)),
  };
}

function projectTable(list: ProjectSummary[]): HTMLElement {
  return h("div", { class: "panel" }, h("table", { class: "data" },
    h("thead", null, h("tr", null, h("th", null, "Project"), h("th", null, "Description"), h("th", { class: "num" }, "Axes"))),
    h("tbody", null, list.length === 0
      ? h("tr", null, h("td", { colspan: "3", class: "muted" }, "No project in the project directory. Create one or import an archive."))
      : list.map((project) => h("tr", { "data-testid": `project-row-${project.name}` },
        h("td", null, h("a", { href: buildPath({ page: "project", project: project.name }) }, project.name)),
        h("td", { class: "wrap" }, project.description),
        h("td", { class: "num" }, String(project.axis_count)))))));
}

function supportedDevices(devices: DictionarySummary[]): HTMLElement {
  return h("div", { class: "panel" }, h("h2", null, "Supported devices"),
    h("div", { class: "panel-body" }, devices.length
      ? devices.map((device, i) => [i ? " · " : "", h("a", { href: buildPath({ page: "dictionary", device: device.device }) }, device.product_name)])
      : h("span", { class: "muted" }, "The dictionary library is empty.")));
}

function newProjectDialog(app: App): void {
  const name = h("input", { type: "text", "data-testid": "new-project-name", autocomplete: "off" });
  const description = h("input", { type: "text", "data-testid": "new-project-description" });
  const busName = h("input", { type: "text", value: "sim" });
  const busSpec = h("input", { type: "text", value: "sim", "data-testid": "new-project-bus" });
  const dialog = formDialog({
    title: "New project",
    body: [
      h("label", { class: "field" }, "Name (also the directory name)", name),
      h("label", { class: "field" }, "Description", description),
      h("div", { class: "grid cols-2" },
        h("label", { class: "field" }, "Bus name", busName),
        h("label", { class: "field" }, "Bus spec (sim, socketcan:can0, serial:/dev/ttyUSB0…)", busSpec)),
    ],
    confirm: "Create",
    confirmTestid: "create-project",
    errorTestid: "dialog-error",
    submit: async () => {
      const buses = busName.value.trim() ? [{ name: busName.value.trim(), interface: busSpec.value.trim(), bitrate: null }] : [];
      opened(app, await projects.create(name.value.trim(), description.value.trim(), buses));
    },
  });
  name.addEventListener("keydown", (event) => {
    if (event.key === "Enter") void dialog.submit();
  });
  name.focus();
}

/** A project that now exists: into the tree, and open it. */
function opened(app: App, project: Project): void {
  app.updateProject(project);
  app.navigate({ page: "project", project: project.name });
}

async function importArchive(app: App): Promise<void> {
  const file = await pickFile(".zip,application/zip");
  if (!file) return;
  try {
    imported(app, await projects.unarchive(file));
  } catch (error) {
    if (error instanceof ApiError && error.status === 409) importAs(app, file, errorText(error));
    else toast(`Import failed: ${errorText(error)}`, "error");
  }
}

function imported(app: App, project: Project): void {
  toast(`Project "${project.name}" imported`, "ok");
  opened(app, project);
}

/** The archive names a project that exists already: ask for another name and import under it. */
function importAs(app: App, file: File, reason: string): void {
  const name = h("input", { type: "text", "data-testid": "import-name", value: `${file.name.replace(/\.zip$/i, "")}-imported` });
  formDialog({
    title: "Import archive",
    body: [h("div", { class: "message warn" }, reason), h("label", { class: "field" }, "Import as project", name)],
    confirm: "Import",
    confirmTestid: "import-confirm",
    errorTestid: "dialog-error",
    submit: async () => imported(app, await projects.unarchive(file, name.value.trim())),
  });
  name.focus();
}
