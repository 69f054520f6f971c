#!/usr/bin/python3
"""Writes the human-readable report of `aerocal flight`.

Usage: aerocal_report.py RESULT_JSON REPORT_HTML [REPORT_PDF]

Reads the flight result (FORMATS.md "Results (JSON)", kind "flight") and writes one
self-contained HTML page (inline CSS, figures as PNG data URIs): readable with no network.
Exit status 0 on success; 2 with a one-line "error: ..." on stderr when the input is not a flight
result (nothing is written); 1 on an internal error. The page is written to a temporary file
beside REPORT_HTML and renamed, so a reader never sees a partial report. REPORT_PDF, when given,
is the same page typeset for A4 by weasyprint (Debian's `weasyprint`; print rules of the inline
style sheet: "page x of y" on every page, tables in a smaller font), written when weasyprint is
installed; without it a note on stderr says so and only the HTML is written (exit 0).
"""
import os
import sys

sys.dont_write_bytecode = True  # keep the source tree free of __pycache__
DEBIAN_PYTHON = "/usr/bin/python3"


def _import_plotting():
    """matplotlib and numpy come from Debian (python3-matplotlib, python3-numpy). Another python3
    first in PATH (a virtualenv, pyenv) may lack them: then rerun under Debian's interpreter."""
    try:
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
        return
    except ImportError as e:
        missing = e.name
    here = os.path.realpath(sys.executable or "")
    if os.path.exists(DEBIAN_PYTHON) and here != os.path.realpath(DEBIAN_PYTHON):
        os.execv(DEBIAN_PYTHON, [DEBIAN_PYTHON, os.path.abspath(__file__)] + sys.argv[1:])
    sys.stderr.write(f"error: the Python module {missing} is missing "
                     "(install the Debian packages python3-matplotlib python3-numpy)\n")
    sys.exit(1)


def write_atomically(path, content):
    directory = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(directory, f".{os.path.basename(path)}.tmp{os.getpid()}")
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(content)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


SECTIONS = [("summary", "Summary"), ("project", "Project"), ("stitching", "Stitching"),
            ("adjustments", "Adjustments"), ("left-out", "Left out"), ("comparison", "Comparison"),
            ("calibration", "Calibration and distortion"), ("residuals", "Image residuals"),
            ("check-map", "Check-point errors")]
RESOLUTION = ("resolution", "Dynamic image resolution")  # only with `flight --quality`


def render(doc):
    import report_adjustments as adj
    import report_facts as facts
    import report_resolution as res
    import report_sections as sec
    from report_html import esc, page

    what = "flight calibration" if doc.get("kind") == "flight" else "block adjustment"
    source = (f'camera {esc(doc.get("camera", "n/a"))}, data {esc(doc.get("data", "n/a"))}'
              if doc.get("kind") == "flight" else f'project {esc(doc.get("project", "n/a"))}')
    toc = SECTIONS + ([RESOLUTION] if isinstance(doc.get("dynamic_image_resolution"), dict) else [])
    parts = [f"<h1>aerocal {what} report</h1>",
             f'<p class="note">{source}, aerocal {esc(doc.get("aerocal_version", "n/a"))}</p>',
             "<nav><ol>" + "".join(f'<li><a href="#{a}">{t}</a></li>' for a, t in toc) + "</ol></nav>"]
    for section in (sec.summary, facts.facts, sec.stitching, adj.adjustments, adj.left_out, adj.comparison,
                    adj.calibration, adj.residual_plot, adj.check_map, res.resolution):
        try:
            parts.append(section(doc))
        except (KeyError, TypeError, ValueError, IndexError, AttributeError, ZeroDivisionError) as e:
            # A malformed section must not cost the reader the rest of the report.
            sys.stderr.write(f"warning: section {section.__name__} not rendered: {e!r}\n")
            parts.append(f'<p class="na">Section {esc(section.__name__)} could not be read from the result '
                         f"({esc(repr(e))}).</p>")
    return page(f"aerocal {what} report", "\n".join(parts))


def write_pdf(html, path):
    """The page typeset by weasyprint, written atomically."""
    import weasyprint

    directory = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(directory, f".{os.path.basename(path)}.tmp{os.getpid()}")
    # The embedded font subsets carry a 'modified' time (fontTools: SOURCE_DATE_EPOCH when set):
    # fixed, so the same report gives the same PDF byte for byte.
    os.environ.setdefault("SOURCE_DATE_EPOCH", "0")
    try:
        weasyprint.HTML(string=html, base_url=directory).write_pdf(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def main(argv):
    if len(argv) not in (3, 4):
        sys.stderr.write("error: usage: aerocal_report.py RESULT_JSON REPORT_HTML [REPORT_PDF]\n")
        return 2
    _import_plotting()
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import report_data

    try:
        doc = report_data.load(argv[1])
    except report_data.InputError as e:
        sys.stderr.write(f"error: {e}\n")
        return 2
    html = render(doc)
    try:
        write_atomically(argv[2], html)
    except OSError as e:
        sys.stderr.write(f"error: {argv[2]}: cannot write the report ({e.strerror})\n")
        return 2
    if len(argv) == 4:
        try:
            write_pdf(html, argv[3])
        except ImportError:
            sys.stderr.write(f"note: {argv[3]} not written: the PDF needs weasyprint (Debian package "
                             "weasyprint, tools/setup.sh installs it)\n")
        except OSError as e:
            sys.stderr.write(f"error: {argv[3]}: cannot write the report ({e.strerror})\n")
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
