/** "Commissioning report": downloads the standalone HTML report of a project or of one axis (docs/report.md). */

import { reportUrl } from "../../client/report";
import { h } from "../../lib/dom";
import { download } from "../ui";

export function reportButton(project: string, axis?: string): HTMLElement {
  const what = axis === undefined ? `project ${project} (every axis)` : `axis ${axis}`;
  return h("button", {
    "data-testid": "report-download",
    title: `Download the commissioning report of ${what}: one HTML file that opens and prints with no server`,
    onclick: () => download(reportUrl(project, axis)),
  }, "Commissioning report");
}
