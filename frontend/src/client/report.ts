/** The commissioning report's download (`GET /api/projects/{p}/report?axis=`, docs/report.md): one standalone HTML file. */

const e = encodeURIComponent;

/** The report of the whole project, or of one of its axes. */
export function reportUrl(project: string, axis?: string): string {
  return `/api/projects/${e(project)}/report${axis === undefined ? "" : `?axis=${e(axis)}`}`;
}
