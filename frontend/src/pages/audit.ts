/**
 * The audit log: every write to a drive or project (who, when, axis, object, old → new, result) and every motion
 * start and stop, newest first, filtered by axis, user, action and time, a page at a time, and exported as CSV or
 * JSON lines (docs/security.md, Audit log). The filters live in the URL, so a filtered view is a link.
 */

import type { Page, PageContext } from "../app";
import { auditApi, type AuditEntry, type AuditFilters, type AuditPage } from "../client/control";
import { download, errorText } from "../components/ui";
import { h, state, type State } from "../lib/dom";
import type { Location } from "../lib/router";

const PAGE_SIZE = 100;
const FILTERS: [keyof AuditFilters, string, string][] = [
  ["axis", "Axis", "BUS:NODE, e.g. sim:1"],
  ["user", "User", "name"],
  ["action", "Action", "drive_write, project_write, arm, enable, stop, quick_stop, take_over…"],
  ["since", "Since", "2h, 7d or 2026-12-01T10:00"],
  ["until", "Until", "ISO 8601 time"],
];

export async function auditPage(context: PageContext): Promise<Page> {
  const view = new AuditView(context);
  await view.load(filtersOf(context.location));
  return { title: "Audit log", element: view.element, update: (location) => view.update(location) };
}

function filtersOf(location: Location): AuditFilters {
  const query = location.query;
  return Object.fromEntries(FILTERS.map(([key]) => [key, query[key] ?? ""]).filter(([, value]) => value));
}

class AuditView {
  readonly element: HTMLElement;
  private readonly page = state<AuditPage | null>(null);
  private readonly problem = state<string | null>(null);
  private readonly fields = new Map<keyof AuditFilters, HTMLInputElement>();
  private filters: AuditFilters = {};
  private offset = 0;

  constructor(private readonly context: PageContext) {
    this.element = h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Audit log"), h("span", { class: "grow" }),
        h("button", { "data-testid": "audit-export-csv", onclick: () => download(auditApi.exportUrl(this.filters, "csv")) }, "Export CSV"),
        h("button", { "data-testid": "audit-export-jsonl", onclick: () => download(auditApi.exportUrl(this.filters, "jsonl")) }, "Export JSON lines")),
      h("p", { class: "muted", style: { margin: "0" } },
        "Every write to a drive or a project — who, when, which axis and object, old → new, result — and every arm, enable, stop, quick stop and take-over. The server only appends to it."),
      this.filterBar(),
      () => (this.problem.val ? h("div", { class: "message error", "data-testid": "audit-error" }, this.problem.val) : null),
      h("div", { class: "panel", style: { overflow: "auto" } }, entriesTable(this.page)),
      h("div", { class: "toolbar" },
        h("button", { "data-testid": "audit-newer", disabled: () => this.offsetOf(this.page.val) === 0, onclick: () => void this.turn(-PAGE_SIZE) }, "Newer"),
        h("span", { class: "muted", "data-testid": "audit-range" }, () => rangeText(this.page.val, this.offsetOf(this.page.val))),
        h("button", { "data-testid": "audit-older", disabled: () => !this.hasOlder(this.page.val), onclick: () => void this.turn(PAGE_SIZE) }, "Older")));
  }

  async load(filters: AuditFilters, offset = 0): Promise<void> {
    this.filters = filters;
    this.offset = offset;
    for (const [key, input] of this.fields) input.value = filters[key] ?? "";
    try {
      this.page.val = await auditApi.page(filters, offset, PAGE_SIZE);
      this.problem.val = null;
    } catch (error) {
      this.problem.val = errorText(error);
    }
  }

  update(location: Location): boolean {
    void this.load(filtersOf(location));
    return true;
  }

  private filterBar(): HTMLElement {
    const inputs = FILTERS.map(([key, label, hint]) => {
      const input = h("input", { type: "text", placeholder: hint, "data-testid": `audit-filter-${key}`, style: { width: "180px" } });
      this.fields.set(key, input);
      return h("label", { class: "field" }, label, input);
    });
    const apply = () => {
      const filters: AuditFilters = Object.fromEntries([...this.fields].map(([key, input]) => [key, input.value.trim()]));
      this.context.app.replaceQuery({ ...filters });  // the filtered view is a link
      void this.load(filters);
    };
    return h("form", { class: "toolbar", onsubmit: (event: Event) => { event.preventDefault(); apply(); } },
      inputs, h("button", { type: "submit", class: "primary", "data-testid": "audit-apply" }, "Show"));
  }

  private offsetOf(page: AuditPage | null): number {
    return page ? page.offset : 0;
  }

  private hasOlder(page: AuditPage | null): boolean {
    return page !== null && page.offset + page.entries.length < page.total;
  }

  private turn(step: number): Promise<void> {
    return this.load(this.filters, Math.max(0, this.offset + step));
  }
}

function entriesTable(page: State<AuditPage | null>): HTMLElement {
  const titles = ["Time", "User", "Action", "Axis / project", "Object", "Old → new", "Result", "Detail"];
  return h("table", { class: "data", "data-testid": "audit-table" },
    h("thead", null, h("tr", null, titles.map((title) => h("th", null, title)))),
    h("tbody", null, () => {
      const entries = (page.val?.entries ?? []) as unknown as AuditEntry[];
      if (entries.length === 0) return h("tr", null, h("td", { colspan: String(titles.length), class: "muted" }, "No entry matches."));
      return entries.map(entryRow);
    }));
}

function entryRow(entry: AuditEntry): HTMLElement {
  const where = entry.axis ?? [entry.project, entry.project_axis].filter(Boolean).join(" / ");
  const change = entry.old === undefined && entry.new === undefined ? "" : `${shown(entry.old)} → ${shown(entry.new)}`;
  return h("tr", { "data-testid": `audit-entry-${entry.seq}`, class: entry.result === "refused" || entry.result === "failed" ? "bad" : "" },
    h("td", { class: "mono" }, entry.time.replace("T", " ").replace("Z", "")),
    h("td", null, entry.user ?? ""),
    h("td", null, entry.action),
    h("td", { class: "mono" }, where),
    h("td", { class: "mono" }, [entry.object, entry.name].filter(Boolean).join(" ")),
    h("td", { class: "mono" }, change),
    h("td", null, entry.result ?? ""),
    h("td", { class: "wrap" }, entry.detail ?? ""));
}

function shown(value: unknown): string {
  return value === null || value === undefined ? "—" : typeof value === "string" ? value : JSON.stringify(value);
}

function rangeText(page: AuditPage | null, offset: number): string {
  if (!page) return "";
  if (page.total === 0) return "no entries";
  return `${offset + 1}–${offset + page.entries.length} of ${page.total}`;
}
