#!/usr/bin/env python3
"""Self-calibrate several flights and tabulate the camera parameters with their sigmas.

    python3 tabulate_flights.py PROJECT [PROJECT ...] [--parameters c,x0,y0,K1] [--csv table.csv]

Each PROJECT is adjusted as `aerocal adjust --project PROJECT --self-calibration all` would; the
table gives per flight sigma0, validity, each parameter and its sigma (empty when held or unknown)
and the check-point RMSE. Numbers are written with repr(): the exact doubles of the results.
"""
import argparse
import csv
import sys

import aerocal


def row_of(project, parameters, self_calibration):
    result = aerocal.adjust(aerocal.Block.read(project), self_calibration=self_calibration)
    camera = result.cameras[0]
    row = {"project": project, "sigma0": repr(result.sigma0), "valid": result.valid}
    for name in parameters:
        sigma = camera.sigma[name]
        row[name] = repr(camera.estimated[name])
        row[f"s_{name}"] = "" if sigma is None else repr(sigma)
    for axis, value in zip("XYZ", result.check_rmse_m):
        row[f"check_rmse_{axis}_m"] = repr(float(value))
    return row


def write_table(out, rows):
    writer = csv.DictWriter(out, list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("projects", nargs="+")
    parser.add_argument("--parameters", default="c,x0,y0,K1")
    parser.add_argument("--self-calibration", default="all")
    parser.add_argument("--csv", help="write the CSV table there (stdout then gets a short summary)")
    args = parser.parse_args()
    parameters = args.parameters.split(",")
    try:
        rows = [row_of(p, parameters, args.self_calibration) for p in args.projects]
    except (ValueError, KeyError) as error:
        print(error, file=sys.stderr)
        return 2
    if args.csv:
        with open(args.csv, "w", newline="") as out:
            write_table(out, rows)
        for row in rows:
            print("  ".join(f"{k}={row[k]}" for k in ["project", "sigma0", "valid"] + parameters))
    else:
        write_table(sys.stdout, rows)
    return 0 if all(row["valid"] for row in rows) else 3


if __name__ == "__main__":
    sys.exit(main())
