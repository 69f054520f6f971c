"""Acceptance of what people read (issue 33): the ODM block's and a flight's reports and a test
field's certificate, rendered as a reader sees them (HTML -> PNG with headless chromium, PDF -> PNG
with pdftoppm): the sections exist and nothing overflows the page box.

Overflow is measured, not guessed: in the HTML, chromium lays the page out at a window width and
a probe script reports how far any element reaches past the viewport (0 when nothing does); in a
PDF, every page is rasterised and its ink must stay inside the page's margins. The PNGs are kept
in $AEROCAL_RENDER_DIR when set (to look at them), else in a temporary folder.

Run by ctest as tools/render (labels render, long: chromium takes seconds per page), or from
tests/tools: python3 -m unittest -v render_test. Skips with a message without chromium
(Debian package chromium), pdftoppm (poppler-utils) or weasyprint (the report's PDF).
With AEROCAL_RENDER_PARTS=pdf only the PDFs are rasterised and checked (and the HTML's sections
looked up, not laid out): ctest's tools/render_pdf, in the CI suite, which installs no chromium.
"""
import json
import os
import re
import shutil
import subprocess
import tempfile
import unittest

import aerocal_runs as runs

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
PDFTOPPM = shutil.which("pdftoppm")
WIDTH_PX = 1240        # the report's design width (max-width 1180 px + padding)
RASTER_DPI = 50
MARGIN_MM = 10         # ink closer than this to a page edge is past the margins (ours are 12 mm+)
HTML_LAYOUT = "html" in os.environ.get("AEROCAL_RENDER_PARTS", "html,pdf").split(",")

PROBE = """<script>
window.addEventListener("load", function () {
  var w = document.documentElement.clientWidth, worst = 0, what = "";
  document.querySelectorAll("body *").forEach(function (e) {
    var r = e.getBoundingClientRect();
    if (r.width > 0 && r.right - w > worst) { worst = r.right - w; what = e.tagName + "#" + (e.id || ""); }
  });
  var p = document.createElement("pre"); p.id = "aerocal-layout";
  p.textContent = JSON.stringify({client: w, scroll: document.documentElement.scrollWidth,
                                  overflow_px: worst, element: what});
  document.body.appendChild(p);
});
</script>"""


def chromium(*args):
    return subprocess.run([CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                           *args], capture_output=True, text=True, timeout=180)


def layout(html_path, width):
    """{client, scroll, overflow_px, element} of the page laid out at `width` px."""
    probe = html_path + ".probe.html"
    with open(html_path, encoding="utf-8") as f, open(probe, "w", encoding="utf-8") as g:
        g.write(f.read().replace("</body>", PROBE + "</body>"))
    r = chromium(f"--window-size={width},900", "--virtual-time-budget=10000", "--dump-dom", "file://" + probe)
    os.remove(probe)
    found = re.search(r'<pre id="aerocal-layout">(.*?)</pre>', r.stdout, re.S)
    if not found:
        raise AssertionError(f"chromium laid out no page for {html_path}: {r.stderr[-500:]}")
    return json.loads(found.group(1))


def screenshot(html_path, png_path, width=WIDTH_PX, height=2400):
    chromium(f"--window-size={width},{height}", f"--screenshot={png_path}", "file://" + html_path)
    return os.path.exists(png_path)


def pdf_pages(pdf_path, prefix):
    """The PDF's pages as PNG files (pdftoppm)."""
    subprocess.run([PDFTOPPM, "-r", str(RASTER_DPI), "-png", pdf_path, prefix], check=True, timeout=180)
    folder, stem = os.path.split(prefix)
    return sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.startswith(stem + "-") and f.endswith(".png"))


def ink_box(png_path):
    """(left, top, right, bottom) in px of everything not white on the page, and the page size."""
    import matplotlib.image
    import numpy

    a = matplotlib.image.imread(png_path)[:, :, :3]
    ink = a.min(axis=2) < 0.85
    cols, rows = numpy.where(ink.any(axis=0))[0], numpy.where(ink.any(axis=1))[0]
    if not len(cols):
        return None, a.shape[1], a.shape[0]
    return (int(cols.min()), int(rows.min()), int(cols.max()), int(rows.max())), a.shape[1], a.shape[0]


class Rendered(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if HTML_LAYOUT and not CHROMIUM:
            raise unittest.SkipTest("chromium is not installed (Debian package chromium): nothing rendered")
        if not PDFTOPPM:
            raise unittest.SkipTest("pdftoppm is not installed (Debian package poppler-utils)")
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.environ.get("AEROCAL_RENDER_DIR") or cls.tmp.name
        os.makedirs(cls.out, exist_ok=True)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def check_html(self, html, name, ids):
        with open(html, encoding="utf-8") as f:
            text = f.read()
        for element in ids:
            self.assertTrue(f'id="{element}"' in text, f"{name}: section {element} missing")
        if not HTML_LAYOUT:
            return  # AEROCAL_RENDER_PARTS without html: the PDF is the rendered check
        for width in (WIDTH_PX,):  # A4 is checked on the PDF (print rules)
            box = layout(html, width)
            self.assertLessEqual(box["overflow_px"], 1, f"{name} at {width} px: {box}")
            self.assertLessEqual(box["scroll"], box["client"], f"{name} at {width} px: {box}")
        self.assertTrue(screenshot(html, os.path.join(self.out, f"{name}.png")))

    def check_pdf(self, pdf, name, min_pages=1):
        pages = pdf_pages(pdf, os.path.join(self.out, f"{name}-pdf"))
        self.assertGreaterEqual(len(pages), min_pages, name)
        margin = MARGIN_MM / 25.4 * RASTER_DPI
        for k, page in enumerate(pages, 1):
            box, width, height = ink_box(page)
            self.assertIsNotNone(box, f"{name} page {k} is blank")
            left, top, right, bottom = box
            self.assertGreaterEqual(left, margin, f"{name} page {k}: ink left of the margin ({box}, {width} px)")
            self.assertLessEqual(right, width - margin, f"{name} page {k}: ink right of the margin ({box}, {width} px)")
            # The certificate's running title (@top-left) and the page number ("page x of y",
            # @bottom-right) sit in the page margins by design: half the margin from the edge at least.
            self.assertGreaterEqual(top, margin / 2, f"{name} page {k}: ink above the margin ({box})")
            self.assertLessEqual(bottom, height - margin / 2, f"{name} page {k}: ink below the margin ({box})")
        return pages


REPORT_SECTIONS = ["summary", "verdict", "advice", "project", "project-facts", "stitching", "adjustments",
                   "left-out", "comparison", "calibration", "residuals", "check-map"]


class OdmReport(Rendered):
    def test_odm_block_report(self):
        block = runs.odm_block(self.tmp.name)
        if block is None:
            self.skipTest("../shared/data/odm_br_uav_gcp_block is absent")
        html, pdf = os.path.join(self.out, "odm_report.html"), os.path.join(self.out, "odm_report.pdf")
        runs.report(block[1], html, pdf if weasyprint_available() else None)
        self.check_html(html, "odm_report", REPORT_SECTIONS + ["adj-self-calibration-control-points",
                                                               "adj-self-calibration-check-points",
                                                               "adj-self-calibration-exposures",
                                                               "adj-self-calibration-rejected", "left-out-table"])
        if weasyprint_available():
            self.check_pdf(pdf, "odm_report", min_pages=3)


class FlightReport(Rendered):
    def test_flight_report(self):
        # The flight result: $AEROCAL_FLIGHT_RESULT (e.g. the example flight's out/example/report/
        # result.json), else the report fixture (real stitching output, tests/data/report).
        result = os.environ.get("AEROCAL_FLIGHT_RESULT") or runs.FIXTURE
        html, pdf = os.path.join(self.out, "flight_report.html"), os.path.join(self.out, "flight_report.pdf")
        runs.report(result, html, pdf if weasyprint_available() else None)
        self.check_html(html, "flight_report", REPORT_SECTIONS + ["stitch-model-comparison", "residual-plot"])
        if weasyprint_available():
            self.check_pdf(pdf, "flight_report", min_pages=3)


class TestFieldCertificate(Rendered):
    def test_certificate(self):
        cert = runs.test_field_certificate(self.tmp.name)
        html = os.path.join(cert, "certificate.html")
        with open(html, encoding="utf-8") as f:
            text = f.read()
        for heading in ("Identification", "Results", "Uncertainty budget", "Distortion", "Stability over image groups",
                        "Check points"):
            self.assertTrue(heading in text, f"certificate: {heading} missing")
        self.check_html(html, "certificate", [])
        shutil.copy(html, os.path.join(self.out, "certificate.html"))
        self.check_pdf(os.path.join(cert, "certificate.pdf"), "certificate", min_pages=2)


def weasyprint_available():
    r = subprocess.run([runs.PYTHON, "-c", "import weasyprint"], capture_output=True)
    return r.returncode == 0


if __name__ == "__main__":
    unittest.main()
