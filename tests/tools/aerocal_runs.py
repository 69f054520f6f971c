"""Runs of the `aerocal` program shared by the Python tests of the report outputs (tables_test,
render_test): the real ODM UAV block adjusted as a user would, a simulated test field calibrated
and certified. Paths come from the environment ctest sets (tests/tools/report_outputs.cmake)."""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
AEROCAL = os.environ.get("AEROCAL_BINARY", os.path.join(ROOT, "build", "tools", "aerocal"))
SHARED = os.environ.get("AEROCAL_SHARED_DATA_DIR") or os.path.join(ROOT, "..", "shared", "data")
REPORT = os.path.join(ROOT, "tools", "report", "aerocal_report.py")
# Debian's interpreter (matplotlib, weasyprint from Debian packages), as aerocal runs the scripts.
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
FIXTURE = os.path.join(ROOT, "tests", "data", "report", "result.json")
# Canon PowerShot SX260 HS of the ODM block: 4000 x 3000 px, f = 4.5 mm ~ 2904 px (its README).
ODM_CAMERA = """name: Canon PowerShot SX260 HS
model: brown_fraser_10
pixel_size_mm: 0.0015495867768595042
format_px: [4000, 3000]
interior: {c: 4.5, x0: 0, y0: 0, K1: 0, K2: 0, K3: 0, P1: 0, P2: 0, B1: 0, B2: 0}
"""


def aerocal(*args, ok=(0,)):
    r = subprocess.run([AEROCAL] + [str(a) for a in args], capture_output=True, text=True, timeout=600)
    if r.returncode not in ok:
        raise AssertionError(f"aerocal {' '.join(map(str, args))}: exit {r.returncode}\n{r.stderr}")
    return r


def odm_block(tmp):
    """(project folder, adjust result) of the ODM block, or None when the shared data is absent.
    The author's control subset, the other targets check points, gross errors in the list: robust
    start, conventional and auto self-calibration compared (exit 0 or 3: valid or not, both are
    reports)."""
    data = os.path.join(SHARED, "odm_br_uav_gcp_block", "odm_gcp_br")
    if not os.path.isdir(data):
        return None
    camera = os.path.join(tmp, "canon.yaml")
    with open(camera, "w") as f:
        f.write(ODM_CAMERA)
    project, result = os.path.join(tmp, "odm"), os.path.join(tmp, "odm.json")
    aerocal("import", "odm", "--gcp-list", os.path.join(data, "gcp_list_floatxy_raw.txt"), "--camera", camera,
            "--control", os.path.join(data, "gcp_list_raw.txt"), "--crs", "EPSG:32722", "--out", project)
    aerocal("adjust", "--project", project, "--robust-start", "--compare", "--self-calibration", "auto",
            "--out", result, "--write-camera", os.path.join(tmp, "canon_calibrated.yaml"), ok=(0, 3))
    return project, result


def test_field_certificate(tmp):
    """The certificate folder of a simulated test field (2 groups of 4 images), without a lab file."""
    field = os.path.join(tmp, "tf")
    aerocal("simulate", "--test-field", "--groups", 2, "--images-per-group", 4, "--out", field)
    aerocal("calibrate", "--camera", os.path.join(field, "camera_nominal.yaml"), "--observations",
            os.path.join(field, "observations.csv"), "--points", os.path.join(field, "points.csv"), "--groups",
            os.path.join(field, "groups.csv"), "--out", os.path.join(field, "cal.json"))
    aerocal("certificate", "--result", os.path.join(field, "cal.json"), "--out", os.path.join(field, "cert"))
    return os.path.join(field, "cert")


def report(result, html, pdf=None):
    args = [PYTHON, REPORT, result, html] + ([pdf] if pdf else [])
    r = subprocess.run(args, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        raise AssertionError(f"report of {result}: exit {r.returncode}\n{r.stderr}")
