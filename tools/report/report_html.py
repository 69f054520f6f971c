"""Small HTML building blocks of the report: escaping, number formatting, tables, inline CSS.

The page is one self-contained file: the style sheet is inline and the figures are PNG data URIs,
so it reads the same offline, from a mail attachment or an archive.
"""
import html

NOT_AVAILABLE = "n/a"

CSS = """
body { font-family: "DejaVu Sans", Arial, Helvetica, sans-serif; color: #1d232b; margin: 0 auto;
       max-width: 1180px; padding: 0 18px 40px; line-height: 1.4; font-size: 14px; }
h1 { font-size: 24px; margin: 22px 0 4px; }
h2 { font-size: 19px; border-bottom: 2px solid #3b6ea8; padding-bottom: 3px; margin-top: 34px; }
h3 { font-size: 16px; margin: 22px 0 6px; color: #24476e; }
h4 { font-size: 14px; margin: 14px 0 4px; }
p.note, div.note { color: #4a5563; font-size: 13px; margin: 4px 0 8px; }
p.na { color: #8a5a00; background: #fff6e0; padding: 4px 8px; border-left: 3px solid #e0a000; }
nav ol { columns: 2; font-size: 13px; }
table { border-collapse: collapse; margin: 6px 0 12px; font-size: 13px; }
caption { text-align: left; font-weight: bold; padding: 2px 0 4px; }
th, td { border: 1px solid #c9d1db; padding: 3px 7px; vertical-align: top; }
th { background: #eaf0f7; text-align: left; font-weight: 600; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap;
         font-family: "DejaVu Sans Mono", monospace; font-size: 12px; }
td.text-small { font-size: 12px; color: #333; max-width: 520px; }
tr.chosen td { background: #e9f6e9; }
tr.flagged td { background: #fdeaea; }
span.ok { color: #1d7a1d; font-weight: bold; }
span.bad { color: #b21f1f; font-weight: bold; }
p.verdict { font-size: 16px; font-weight: bold; padding: 6px 10px; border-left: 5px solid; }
p.verdict.ok { color: #1d7a1d; background: #e9f6e9; }
p.verdict.warn { color: #8a5a00; background: #fff6e0; }
p.verdict.bad { color: #b21f1f; background: #fdeaea; }
td.hash { font-family: "DejaVu Sans Mono", monospace; font-size: 10px; word-break: break-all; max-width: 260px; }
td.text-small { word-break: break-word; }
details > summary { cursor: pointer; font-weight: 600; margin: 6px 0; }
figure { margin: 10px 0 18px; }
figure img { max-width: 100%; border: 1px solid #d5dbe3; }
figcaption { font-size: 13px; color: #4a5563; margin-top: 3px; }
@page { size: A4; margin: 14mm 12mm 16mm 12mm;
        @bottom-right { content: "page " counter(page) " of " counter(pages); font-size: 8pt; color: #4a5563; } }
@media print {
  body { max-width: none; padding: 0; font-size: 9pt; }
  h2 { break-after: avoid; } caption { break-after: avoid; }
  table { font-size: 7pt; max-width: 100%; } td.num { font-size: 7pt; } td.hash { font-size: 6pt; max-width: 60mm; }
  th, td { padding: 1px 3px; }
  td.text-small { font-size: 6.5pt; max-width: none; } td details { display: none; }
  /* The second line of a number cell (e.g. "r = 1986; F = 171 > 1.94") may wrap on paper: wide
     tables (the model choice per exposure) stay inside the page. */
  td.num small { white-space: normal; }
  /* A folded list stays folded on paper: its summary line is printed, the rows are in the HTML
     report and in `aerocal export --tables`. */
  details:not([open]) > :not(summary) { display: none; }
  details:not([open]) > summary::after { content: " (full list: HTML report, aerocal export --tables)";
                                          font-weight: normal; color: #4a5563; }
  figure { break-inside: avoid; } figure img { max-width: 100%; }
  nav { display: none; }
}
"""


def esc(x):
    return html.escape(str(x), quote=True)


def fmt(x, spec=".4f"):
    """Formats a number; None (absent or not finite) shows as n/a."""
    if x is None:
        return NOT_AVAILABLE
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int) or (isinstance(x, float) and x.is_integer() and spec == "d"):
        return str(int(x))
    if x == 0 and spec[-1] in "eg":  # 0.0000e+00 reads worse than 0
        return "0"
    try:
        return format(x, spec)
    except (TypeError, ValueError):
        return esc(x)


def yes_no(x):
    if x is None:
        return NOT_AVAILABLE
    return '<span class="ok">yes</span>' if x else '<span class="bad">no</span>'


class Cell:
    """A table cell with raw (already escaped) HTML and a CSS class."""

    def __init__(self, content, css="", attrs=""):
        self.content, self.css, self.attrs = content, css, attrs


def num(x, spec=".4f"):
    return Cell(fmt(x, spec), "num")


def text(x, css=""):
    return Cell(esc(x), css)


def raw(content, css=""):
    return Cell(content, css)


def table(table_id, caption, headers, rows, row_classes=None):
    """headers: list of str (escaped here); rows: list of lists of Cell or str (escaped)."""
    out = [f'<table id="{esc(table_id)}">', f"<caption>{esc(caption)}</caption>", "<thead><tr>"]
    out += [f"<th>{esc(h)}</th>" for h in headers]
    out.append("</tr></thead><tbody>")
    for k, row in enumerate(rows):
        css = row_classes[k] if row_classes and row_classes[k] else ""
        out.append(f'<tr class="{css}">' if css else "<tr>")
        for cell in row:
            if not isinstance(cell, Cell):
                cell = text(cell)
            cls = f' class="{cell.css}"' if cell.css else ""
            out.append(f"<td{cls}{cell.attrs}>{cell.content}</td>")
        out.append("</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def not_available(what):
    return f'<p class="na">{esc(what)}: not available in this result.</p>'


def note(content_html):
    return f'<p class="note">{content_html}</p>'


def figure(figure_id, png_base64, alt, caption_html):
    return (f'<figure id="{esc(figure_id)}"><img src="data:image/png;base64,{png_base64}" '
            f'alt="{esc(alt)}"><figcaption>{caption_html}</figcaption></figure>')


def page(title_text, body_html):
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{esc(title_text)}</title><style>{CSS}</style></head><body>\n"
            f"{body_html}\n</body></html>\n")
