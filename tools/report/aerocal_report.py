#!/usr/bin/python3
"""Writes the human-readable report of `aerocal flight`.

Usage: aerocal_report.py RESULT_JSON REPORT_HTML

Reads the flight result (FORMATS.md "Results (JSON)", kind "flight") and writes one
self-contained HTML page (inline CSS, figures as PNG data URIs): readable with no network.
Exit status 0 on success; 2 with a one-line "error: ..." on stderr when the input is not a flight
result (nothing is written); 1 on an internal error. The page is written to a temporary file
beside REPORT_HTML and renamed, so a reader never sees a partial report.
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


def render(doc):
    import report_adjustments as adj
    import report_sections as sec
    from report_html import esc, page

    parts = [f"<h1>aerocal flight calibration report</h1>"
             f'<p class="note">camera {esc(doc.get("camera", "n/a"))}, data {esc(doc.get("data", "n/a"))}'
             f', aerocal {esc(doc.get("aerocal_version", "n/a"))}</p>',
             "<nav><ol>"
             '<li><a href="#summary">Summary</a></li><li><a href="#stitching">Stitching</a></li>'
             '<li><a href="#adjustments">Adjustments</a></li><li><a href="#comparison">Comparison</a></li>'
             '<li><a href="#calibration">Calibration and distortion</a></li>'
             '<li><a href="#residuals">Image residuals</a></li><li><a href="#check-map">Check-point errors</a></li>'
             "</ol></nav>"]
    for section in (sec.summary, sec.stitching, adj.adjustments, adj.comparison, adj.calibration,
                    adj.residual_plot, adj.check_map):
        try:
            parts.append(section(doc))
        except (KeyError, TypeError, ValueError, IndexError, AttributeError, ZeroDivisionError) as e:
            # A malformed section must not cost the reader the rest of the report.
            sys.stderr.write(f"warning: section {section.__name__} not rendered: {e!r}\n")
            parts.append(f'<p class="na">Section {esc(section.__name__)} could not be read from the result '
                         f"({esc(repr(e))}).</p>")
    return page("aerocal flight report", "\n".join(parts))


def main(argv):
    if len(argv) != 3:
        sys.stderr.write("error: usage: aerocal_report.py RESULT_JSON REPORT_HTML\n")
        return 2
    _import_plotting()
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import report_data

    try:
        doc = report_data.load(argv[1])
    except report_data.InputError as e:
        sys.stderr.write(f"error: {e}\n")
        return 2
    try:
        write_atomically(argv[2], render(doc))
    except OSError as e:
        sys.stderr.write(f"error: {argv[2]}: cannot write the report ({e.strerror})\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
