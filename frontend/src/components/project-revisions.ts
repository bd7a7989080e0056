/**
 * The project's kept revisions: the project as it was before each change that replaced many values (a backup of a
 * drive into the project, an upload from the drives, a DCF import, a restore), newest first, with when, by whom
 * and what replaced it; any of them can be restored after a confirmation. The list follows the project's revision.
 */

import { projects, type KeptRevision, type Project } from "../client/api";
import { effect, h, state, untrack, type State } from "../lib/dom";
import { confirmAction, failure, messageView, type Message } from "./ui";

interface RevisionsView {
  project: State<Project>;
  kept: State<KeptRevision[] | null>;
  message: State<Message | null>;
  onRestored: (next: Project) => void;
}

export function revisionsPanel(project: State<Project>, onRestored: (next: Project) => void): HTMLElement {
  const view: RevisionsView = { project, kept: state<KeptRevision[] | null>(null), message: state<Message | null>(null), onRestored };
  let asked = 0;
  effect(() => {
    const { name } = project.val; // every new state of the project (a change keeps a revision, or not)
    const ticket = ++asked;
    untrack(() => void projects.revisions(name).then(
      (list) => { if (ticket === asked) view.kept.val = list; },
      (error: unknown) => { if (ticket === asked) view.message.val = failure(error, "revisions-message"); }));
  });
  return h("div", { class: "panel", "data-testid": "revisions-panel" },
    h("h2", null, "Kept revisions"),
    messageView(view.message),
    h("div", null, () => revisionsTable(view)));
}

function revisionsTable(view: RevisionsView): HTMLElement {
  const kept = view.kept.val;
  if (kept === null) return h("div", { class: "muted" }, "reading…");
  if (kept.length === 0) {
    return h("div", { class: "muted", "data-testid": "revisions-empty" },
      "None yet: a change that replaces many values (a backup of a drive into the project, an upload, a DCF import) keeps the project as it was, to restore here.");
  }
  return h("table", { class: "data", "data-testid": "revisions-table" },
    h("thead", null, h("tr", null, ["Replaced", "By", "What replaced it", "Revision", ""].map((title) => h("th", null, title)))),
    h("tbody", null, kept.map((item) => revisionRow(view, item))));
}

function revisionRow(view: RevisionsView, item: KeptRevision): HTMLElement {
  return h("tr", { "data-testid": "revision-row", "data-revision": item.revision },
    h("td", null, new Date(item.saved_at * 1000).toLocaleString()),
    h("td", null, item.by || h("span", { class: "muted" }, "not recorded")),
    h("td", { class: "wrap" }, item.reason),
    h("td", { class: "mono" }, item.revision),
    h("td", null, h("button", { class: "small", "data-testid": "revision-restore", onclick: () => void restoreRevision(view, item) }, "Restore…")));
}

async function restoreRevision(view: RevisionsView, item: KeptRevision): Promise<void> {
  const project = view.project.rawVal;
  const when = new Date(item.saved_at * 1000).toLocaleString();
  const text = `Make project ${project.name} what it was at revision ${item.revision}, before "${item.reason}" (${when}${item.by ? `, by ${item.by}` : ""})? `
    + "The project as it is now is kept as a revision in turn, so this can be undone.";
  if (!(await confirmAction("Restore project revision", text, "Restore revision"))) return;
  try {
    view.message.val = null;
    const restored = await projects.restoreRevision(project.name, item.revision, project.revision);
    view.onRestored(restored);
    view.message.val = { text: `Project ${project.name} restored to revision ${restored.revision}.`, tone: "ok", testid: "revisions-message" };
  } catch (error) {
    view.message.val = failure(error, "revisions-message");
  }
}
