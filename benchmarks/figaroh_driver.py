"""Run FIGAROH's geometric calibration on a data set written by bench_calibration.py (its own venv).

Usage: .venv-figaroh/bin/python benchmarks/figaroh_driver.py DIR [REPEAT]
(DIR holds robot.urdf, figaroh.csv, figaroh.yaml); prints one JSON object: FIGAROH's residuals, parameters,
median wall time of REPEAT runs. FIGAROH needs a subclass per robot (its cost function) and a config file:
this is the one for a 4-joint SCARA measured by position.
"""

import contextlib
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from figaroh.calibration.base_calibration import BaseCalibration
from figaroh.calibration.calibration_tools import calc_updated_fkm


class Robot:
    def __init__(self, urdf: str) -> None:
        self.model = pin.buildModelFromUrdf(urdf)
        self.data = self.model.createData()
        self.q0 = pin.neutral(self.model)


class ScaraCalibration(BaseCalibration):
    def cost_function(self, var):
        PEEe = calc_updated_fkm(self.model, self.data, var, self.q_measured, self.calib_config)
        return PEEe - self.PEE_measured


def calibrate(d: Path) -> tuple[ScaraCalibration, object]:
    robot = Robot(str(d / "robot.urdf"))
    cal = ScaraCalibration(robot, str(d / "figaroh.yaml"))
    cal.calib_config["data_file"] = str(d / "figaroh.csv")
    cal._data_path = str(d / "figaroh.csv")
    # FIGAROH 1.0.2 reads these two flags but sets neither (its examples do, per robot): the base is the
    # measurement frame (known), the measured point on the tool is not (its offset is identified)
    cal.calib_config["known_baseframe"] = True
    cal.calib_config["known_tipframe"] = False
    cal.initialize()
    with contextlib.redirect_stdout(sys.stderr):  # its quality report
        res = cal.solve(method="lm", max_iterations=1, outlier_threshold=1.0, enable_logging=False)
    return cal, res


def main(folder: str, repeat: int) -> None:
    d = Path(folder)
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        cal, res = calibrate(d)
        walls.append(time.perf_counter() - t0)
    var = res.x
    pred = calc_updated_fkm(cal.model, cal.data, var, cal.q_measured, cal.calib_config)
    r = (pred - cal.PEE_measured).reshape(3, -1).T
    print(json.dumps({"wall": statistics.median(walls), "rms": float(np.sqrt(np.mean(r**2))),
                      "max": float(np.linalg.norm(r, axis=1).max()), "parameters": list(cal.calib_config["param_name"]),
                      "values": [float(v) for v in var], "nfev": int(getattr(res, "nfev", -1))}))


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 1)
