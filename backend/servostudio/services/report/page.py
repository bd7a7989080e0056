"""The report as one standalone HTML document: a table of contents, the project, then one part per axis, with
plotly.js inline so it opens from a file with no server and offline. It prints cleanly: each axis starts a page,
the plots' tool bar and the table of contents' links lose their screen styling, everything reads in black and white.
"""

from __future__ import annotations

from collections.abc import Callable

from servostudio import __version__
from servostudio.services.report import axis_sections, commissioning_sections, plots
from servostudio.services.report.collect import AxisRecord, ProjectRecord
from servostudio.services.report.markup import facts, section, shown, text

STYLE = """
body { font-family: "DejaVu Sans", Arial, sans-serif; font-size: 10.5pt; color: #000; background: #fff;
       max-width: 62rem; margin: 1.5rem auto; padding: 0 1rem; line-height: 1.35; }
h1 { font-size: 1.6rem; margin-bottom: 0.2rem; } h2 { font-size: 1.3rem; border-bottom: 2px solid #000; }
h3 { font-size: 1.1rem; margin-top: 1.4rem; } h4 { font-size: 1rem; margin: 0.8rem 0 0.3rem; }
h5 { font-size: 0.95rem; margin: 0.6rem 0 0.2rem; }
table { border-collapse: collapse; margin: 0.4rem 0; } th, td { border: 1px solid #777; padding: 0.15rem 0.4rem;
        text-align: left; vertical-align: top; } thead th { background: #eee; }
table.facts th { font-weight: normal; background: #f4f4f4; width: 16rem; }
code { font-size: 0.85em; word-break: break-all; }
.absent { font-style: italic; border-left: 3px solid #777; padding-left: 0.5rem; }
.note { margin: 0.6rem 0 0.2rem; } .plot { width: 100%; break-inside: avoid; page-break-inside: avoid; }
nav.toc ol { columns: 2; } nav.toc a { color: #000; }
.generated { color: #333; }
@media print {
  body { max-width: none; margin: 0; font-size: 9.5pt; }
  .axis { break-before: page; page-break-before: always; }
  .modebar, .modebar-container { display: none !important; }
  nav.toc a { text-decoration: none; }
  thead th, table.facts th { background: none; }
  table, .step, section { break-inside: auto; } tr { break-inside: avoid; page-break-inside: avoid; }
  h2, h3, h4, h5 { break-after: avoid; page-break-after: avoid; }
}
"""

Section = tuple[str, str, Callable[[AxisRecord, str], str]]
#: the sections of an axis, in order: anchor suffix, title, what builds it
SECTIONS: tuple[Section, ...] = (
    ("drive", "Drive identity and firmware", lambda record, _: axis_sections.drive(record)),
    ("motor", "Motor", lambda record, _: axis_sections.motor(record)),
    ("phasing", "Phasing", lambda record, _: commissioning_sections.phasing(record)),
    ("plant", "Identified plant", lambda record, _: commissioning_sections.plant(record)),
    ("tuning", "Tuning options and gains before → after", lambda record, _: commissioning_sections.tuning(record)),
    ("steps", "Step responses", commissioning_sections.steps),
    ("bode", "Frequency response (Bode)", commissioning_sections.bode),
    ("parameters", "Parameters that differ from the defaults", lambda record, _: axis_sections.parameters(record)),
    ("files", "Settings files and checksums", lambda record, _: axis_sections.files(record)),
)


def document(record: ProjectRecord) -> str:
    project = record.project
    title = f"Commissioning report — {project.name}" + (
        f" — axis {record.axes[0].axis.name}" if len(record.axes) == 1 and len(project.axes) > 1 else ""
    )
    parts = [_project_part(record), *(_axis_part(record, number, axis) for number, axis in enumerate(record.axes))]
    return (
        f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{text(title)}</title>'
        f"<style>{STYLE}</style>{plots.library()}</head><body>"
        f'<header><h1>{text(title)}</h1><p class="generated">Generated {text(record.generated_at)} by Servo Studio '
        f"{text(__version__)} from the project's files (project revision {text(record.revision)}).</p></header>"
        f"{_contents(record)}{''.join(parts)}</body></html>"
    )


def _contents(record: ProjectRecord) -> str:
    items = ['<li><a href="#project">Project</a></li>']
    for number, axis in enumerate(record.axes):
        anchor = _anchor(number)
        links = "".join(f'<li><a href="#{anchor}-{key}">{text(title)}</a></li>' for key, title, _ in SECTIONS)
        links += f'<li><a href="#{anchor}-history">Who and when</a></li>'
        items.append(f'<li><a href="#{anchor}">Axis {text(axis.axis.name)}</a><ol>{links}</ol></li>')
    return f'<nav class="toc"><h2>Contents</h2><ol>{"".join(items)}</ol></nav>'


def _project_part(record: ProjectRecord) -> str:
    project = record.project
    buses = ", ".join(f"{bus.name} ({bus.interface})" for bus in project.buses) or None
    axes = ", ".join(f"{axis.name} ({axis.device}, node {axis.node_id})" for axis in project.axes) or None
    rows = [("Name", text(project.name)), ("Description", shown(project.description or None)),
            ("Buses", shown(buses)), ("Axes", shown(axes)), ("Revision", text(record.revision))]  # fmt: skip
    body = facts(rows) + axis_sections.checksums(record.files, "The project has no project file.")
    body += "<h3>Who and when</h3>" + axis_sections.audit(record.history, record.audit_available)
    return f'<section id="project"><h2>Project {text(project.name)}</h2>{body}</section>'


def _axis_part(record: ProjectRecord, number: int, axis: AxisRecord) -> str:
    anchor = _anchor(number)
    sections = [section(f"{anchor}-{key}", title, build(axis, f"{anchor}-{key}")) for key, title, build in SECTIONS]
    sections.append(section(f"{anchor}-history", "Who and when", axis_sections.history(axis, record.audit_available)))
    return f'<div class="axis" id="{anchor}"><h2>Axis {text(axis.axis.name)}</h2>{"".join(sections)}</div>'


def _anchor(number: int) -> str:
    """Anchors are numbers, not axis names: a name is user input."""
    return f"axis-{number + 1}"
