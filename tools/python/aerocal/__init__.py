"""aerocal: calibration of large-format and multi-head aerial cameras, from Python.

The C++ library behind the `aerocal` command line, with its objects in Python and numpy arrays
(nothing is implemented twice: every number comes from the same code as the command's).

Cameras
    Camera.read(path, format="auto")  a camera file of any format in formats()
    camera.params / camera.units / camera.sigma   parameters by the model's names
    camera.image_to_ray(pixels) / camera.ray_to_image(rays)   arrays of shape (N, 2)
    convert_camera(camera, model=...) -> (Camera, residual)   into any of models()
    camera.write(path, format=...)

Blocks and the adjustment
    Block.read(project)  or  Block.from_arrays(cameras, exposures, points, observations)
    adjust(block, self_calibration="all", **options) -> AdjustmentResult
    result.sigma0, result.valid, result.check_rmse_m, result.cameras[0].estimated["c"],
    result.cameras[0].sigma["c"], result.correlation, result.residuals, result.to_json()
    result.points, result.exposures   adjusted coordinates (and the exposures' sigmas)
    result.covariance(["camera cam1", "exposure 0012", "point T17"])   the joint sigma0^2 Q,
        cross blocks included (exposure: X, Y, Z m, omega, phi, kappa deg; point: X, Y, Z m)
    adjust(..., progress=lambda done, total: ...)

Sub-image stitching (multi-CCD cameras)
    match(camera_file, {"I": "I.tif", ...}, frame="1") -> {frame, point, subimage, pixel, sigma_px}
    stitch(camera_file, stitch_obs_csv, model="auto") -> StitchResult
    result.frames[i]["subimages"]["II"]["params"], result.stability, result.to_json()

Camera calibration (test field or planar board)
    calibrate(camera_file, observations=..., points=...) or (camera_file, images="b*.jpg",
              board="chessboard:9x6:25") -> CalibrationResult: valid, sigma0, calibration, to_json()
    certificate(result_json, out_folder, lab="lab.yaml") -> (exit code, certificate.json as a dict)

Multi-head rigs
    rig_design(rig_camera_file, height_m=0) -> dict (GSD ratios, formats, zones, tie positions)
    rig_error_analysis(rig_camera_file, limits_file, target="B:100,200") -> dict (maximum error,
               linear propagation, Monte-Carlo)
    rig_stitch(rig_camera_file, project, mode="line") -> RigStitchResult: valid, failures,
               rig_exposures, snooping, to_json()

Pushbroom line cameras
    pushbroom_calibrate(line_camera_file, pos_csv, observations_csv, points_csv, **options)
        -> LineCalibrationResult: valid, sigma0, document, to_json()
    pushbroom_control(line_camera_file, pos_csv, line_image, reference_camera, reference_images,
                      reference_exposures=...) -> dict: document, observations, points (arrays)

The virtual image (resampling the sub-images of one frame)
    resample(camera_file, stitch_json, {"I": "I.tif", ...}, frame="", interpolation="bilinear",
             fill=0, out="") -> numpy array (rows, cols[, bands]), uint8 or uint16

Conventions: pixels (col, row) with the top-left pixel centre at (0, 0); photo coordinates x
right, y up (mm); rays (x / c, y / c) with the camera looking along -z; angles in degrees in
tables, as in the files. Bad input raises InputError (a ValueError) with FILE:LINE; a result that
did not converge or is not valid comes back with valid=False, as the command writes it.
"""

from ._aerocal import (
    AdjustmentResult,
    Block,
    Camera,
    CameraEstimate,
    ConfigError,
    InputError,
    LineCalibrationResult,
    RigStitchResult,
    StitchResult,
    CalibrationResult,
    adjust,
    calibrate,
    certificate,
    convert_camera,
    formats,
    match,
    models,
    pushbroom_calibrate,
    pushbroom_control,
    resample,
    rig_design,
    rig_error_analysis,
    rig_stitch,
    stitch,
)

__all__ = [
    "AdjustmentResult",
    "Block",
    "Camera",
    "CameraEstimate",
    "ConfigError",
    "InputError",
    "LineCalibrationResult",
    "RigStitchResult",
    "StitchResult",
    "CalibrationResult",
    "adjust",
    "calibrate",
    "certificate",
    "convert_camera",
    "formats",
    "match",
    "models",
    "pushbroom_calibrate",
    "pushbroom_control",
    "resample",
    "rig_design",
    "rig_error_analysis",
    "rig_stitch",
    "stitch",
]
