"""Tests of the ratslam Python module, run by ctest with Debian's /usr/bin/python3.

The oracle for replays and sessions is the `ratslam` program itself: a replay from Python and a
session fed the same data set frame by frame must give exactly the command line's experiences.
"""
import csv
import json
import os
import shutil
import signal
import struct
import subprocess
import tempfile
import threading
import unittest
import zlib

import numpy as np

import ratslam

SOURCE = os.environ["RATSLAM_SOURCE_DIR"]
BINARY = os.environ["RATSLAM_BINARY"]
SYNTHETIC_CONFIG = os.path.join(SOURCE, "configs", "synthetic.toml")


def read_grey_png(path):
    """A minimal decoder for the 8-bit grey, non-interlaced PNGs the synthesizer writes
    (no OpenCV for Python in the dependencies)."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert (depth, colour, interlace) == (8, 0, 0), path
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    rows = np.zeros((height, width), dtype=np.uint8)
    previous = np.zeros(width, dtype=np.int32)
    stride = width + 1
    for y in range(height):
        kind = raw[y * stride]
        line = np.frombuffer(raw, dtype=np.uint8, count=width, offset=y * stride + 1).astype(np.int32)
        if kind == 0:
            out = line
        elif kind == 1:  # Sub: what OpenCV writes for these images
            out = np.cumsum(line) & 0xFF
        elif kind == 2:  # Up
            out = (line + previous) & 0xFF
        else:
            raise ValueError(f"{path}: PNG filter {kind} not supported by this test decoder")
        rows[y] = out
        previous = out
    return rows


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class RatslamModuleTest(unittest.TestCase):
    def route22_walks(self, *repetitions):
        """The IPIN 2023 route 22 phone logs of these repetitions; skips the test without them."""
        data = os.path.join(SOURCE, "..", "shared", "data", "ipin2023-t3")
        walks = [os.path.join(data, f"IPIN2023_T3_TrainingTrial22_repetition{r}.txt")
                 for r in repetitions]
        for walk in walks:
            if not os.path.exists(walk):
                self.skipTest(f"missing {walk}")
        return walks

    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="ratslam_python_")
        cls.data = os.path.join(cls.root, "data")
        subprocess.run([BINARY, "synthesize", "--out", cls.data, "--laps", "2"], check=True,
                       capture_output=True)
        cls.cli_run = os.path.join(cls.root, "cli_run")
        subprocess.run([BINARY, "replay", "--quiet", "--data", cls.data, "--out", cls.cli_run,
                        "--config", SYNTHETIC_CONFIG], check=True)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root)

    def assertColumnsMatchCsv(self, columns, rows, names):
        self.assertEqual(len(columns[names[0]]), len(rows))
        for name in names:
            expected = np.array([float(r[name]) for r in rows])
            np.testing.assert_array_equal(columns[name].astype(float), expected, err_msg=name)

    def test_config_defaults_set_and_errors(self):
        config = ratslam.Config()
        self.assertIn("[pose_cells]", config.toml())
        config.set("local_view.decay_per_match", 0.25)
        self.assertEqual(config.to_dict()["local_view"]["decay_per_match"], 0.25)
        config.set("front_end.kind", "fused")
        self.assertEqual(config.to_dict()["front_end"]["kind"], "fused")
        with self.assertRaisesRegex(ratslam.Error, "decay_per_macth"):
            config.set("local_view.decay_per_macth", 1.0)
        with self.assertRaisesRegex(ratslam.Error, "dim_xy_cells"):
            config.set("pose_cells.dim_xy_cells", -3)
        with self.assertRaisesRegex(ratslam.Error, "section.name"):
            config.set("dim_xy_cells", 3)
        # A rejected value leaves the configuration as it was.
        self.assertEqual(config.to_dict()["local_view"]["decay_per_match"], 0.25)
        loaded = ratslam.Config.load(SYNTHETIC_CONFIG)
        self.assertEqual(ratslam.Config.from_toml(loaded.toml()).toml(), loaded.toml())
        with self.assertRaisesRegex(ratslam.Error, "no-such.toml"):
            ratslam.Config.load(os.path.join(self.root, "no-such.toml"))

    def test_replay_equals_the_command_line(self):
        out = os.path.join(self.root, "py_run")
        run = ratslam.replay([self.data], out, config=ratslam.Config.load(SYNTHETIC_CONFIG))
        with open(os.path.join(out, "summary.json")) as f:
            on_disk = json.load(f)
        self.assertEqual(run["summary"]["experiences"], on_disk["experiences"])
        self.assertGreater(run["summary"]["loop_closures"], 0)
        with open(os.path.join(self.cli_run, "experiences.csv")) as a, \
                open(os.path.join(out, "experiences.csv")) as b:
            self.assertEqual(a.read(), b.read())
        self.assertColumnsMatchCsv(run["experiences"],
                                   read_csv(os.path.join(self.cli_run, "experiences.csv")),
                                   ["id", "x_m", "y_m", "theta_rad", "template_id", "time_s"])
        self.assertColumnsMatchCsv(run["links"], read_csv(os.path.join(self.cli_run, "links.csv")),
                                   ["id", "from_id", "to_id", "distance_m", "loop_closure"])
        self.assertEqual(len(run["trajectory"]["time_s"]), on_disk["odometry_steps"])
        # An earlier run's folder is refused without overwrite, as on the command line.
        with self.assertRaisesRegex(ratslam.Error, "overwrite"):
            ratslam.replay([self.data], out, config=ratslam.Config.load(SYNTHETIC_CONFIG))
        with self.assertRaisesRegex(ratslam.Error, "no-such-data"):
            ratslam.replay([os.path.join(self.root, "no-such-data")], os.path.join(self.root, "x"))

    def test_ctrl_c_stops_a_replay_and_keeps_its_outputs(self):
        out = os.path.join(self.root, "interrupted")
        timer = threading.Timer(0.02, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        with self.assertRaises(KeyboardInterrupt) as caught:
            ratslam.replay([self.data], out, config=ratslam.Config.load(SYNTHETIC_CONFIG))
        timer.join()
        self.assertIn("the outputs so far are in", str(caught.exception))
        with open(os.path.join(out, "summary.json")) as f:
            stopped = json.load(f)
        with open(os.path.join(self.cli_run, "summary.json")) as f:
            whole = json.load(f)
        self.assertLess(stopped["frames"], whole["frames"])

    def test_session_fed_frame_by_frame_equals_the_replay(self):
        config = ratslam.Config.load(SYNTHETIC_CONFIG)
        session = ratslam.Session(config)
        odometry = read_csv(os.path.join(self.data, "odometry.csv"))
        images = read_csv(os.path.join(self.data, "images.csv"))
        # The replay's order: at equal times the image comes before the odometry.
        events = [(float(r["time_s"]), 0, r) for r in images] + \
                 [(float(r["time_s"]), 1, r) for r in odometry]
        events.sort(key=lambda e: (e[0], e[1]))
        half = len(events) // 2
        for i, (t, kind, row) in enumerate(events):
            if i == half:
                # Save half way and go on in a new session loaded from the map.
                path = os.path.join(self.root, "half.map")
                session.save_map(path)
                session = ratslam.Session.load(path, config)
            if kind == 0:
                session.image(t, read_grey_png(os.path.join(self.data, "images", row["file"])))
            else:
                session.odometry(t, float(row["forward_speed_m_per_s"]),
                                 float(row["turn_rate_rad_per_s"]))
        self.assertColumnsMatchCsv(session.experiences(),
                                   read_csv(os.path.join(self.cli_run, "experiences.csv")),
                                   ["id", "x_m", "y_m", "theta_rad", "template_id", "time_s"])
        summary = session.summary()
        self.assertGreater(summary["loop_closures"], 0)
        self.assertEqual(session.current_experience, summary["current_experience"])

        # Localisation on the finished map: the map does not grow and places are recognised.
        final = os.path.join(self.root, "final.map")
        session.save_map(final)
        localising = ratslam.Session.load(final, config, localise=True)
        experiences = summary["experiences"]
        for t, kind, row in events[:400]:
            if kind == 0:
                localising.image(t, read_grey_png(os.path.join(self.data, "images", row["file"])))
            else:
                localising.odometry(t, float(row["forward_speed_m_per_s"]),
                                    float(row["turn_rate_rad_per_s"]))
        self.assertEqual(localising.summary()["experiences"], experiences)
        self.assertGreater(localising.summary()["recognitions"], 0)
        self.assertLessEqual(localising.summary()["relocalisations"],
                             localising.summary()["recognitions"])
        lost = localising.localisation()["lost"]
        self.assertEqual(len(lost), 200)
        self.assertLess(lost.mean(), 0.5)

    def test_version_and_bad_replay_arguments(self):
        self.assertRegex(ratslam.__version__, r"^\d+\.\d+\.\d+")
        with self.assertRaisesRegex(ratslam.Error, "until_s must be a finite number"):
            ratslam.replay([self.data], os.path.join(self.root, "nan_run"), until_s=float("nan"))
        with self.assertRaisesRegex(ratslam.Error, "the output folder is an empty path"):
            ratslam.replay([self.data], "", until_s=5.0)
        # Messages speak Python: overwrite=True, not the command line's --overwrite.
        with self.assertRaises(ratslam.Error) as refused:
            ratslam.replay([self.data], self.cli_run, until_s=5.0)
        self.assertIn("overwrite=True", str(refused.exception))
        self.assertNotIn("--overwrite", str(refused.exception))

    def test_session_refuses_bad_input(self):
        session = ratslam.Session(ratslam.Config.load(SYNTHETIC_CONFIG))
        session.odometry(1.0, 0.5, 0.0)
        with self.assertRaisesRegex(ratslam.Error, "time goes backwards"):
            session.odometry(0.5, 0.5, 0.0)
        with self.assertRaisesRegex(ratslam.Error, "2-D uint8"):
            session.image(2.0, np.zeros((4, 4, 3), dtype=np.uint8))
        with self.assertRaisesRegex(ratslam.Error, "finite"):
            session.odometry(3.0, float("nan"), 0.0)
        with self.assertRaisesRegex(ratslam.Error, "finite"):
            session.wifi(4.0, {"aa:bb": float("inf")})
        with self.assertRaisesRegex(ratslam.Error, "takes no descriptors"):
            session.descriptor(5.0, np.ones(4))
        # What a data-set file could not hold is refused here too (it once made NaN poses and a
        # map that could not be read back).
        with self.assertRaisesRegex(ratslam.Error, "forward_speed must be a finite number"):
            session.odometry(6.0, 1e308, 1e308)
        with self.assertRaisesRegex(ratslam.Error, "time_s must be a finite number"):
            session.odometry(1e300, 0.5, 0.0)
        with self.assertRaisesRegex(ratslam.Error, "RSSI of aa:bb must be a finite number"):
            session.wifi(7.0, {"aa:bb": 1e308})
        with self.assertRaisesRegex(ratslam.Error, "heading_rad must be a finite number"):
            session.compass(8.0, 1e308)
        with self.assertRaisesRegex(ratslam.Error, "expected real numbers.*complex"):
            session.descriptor(9.0, np.ones(4, dtype=complex))
        floors = ratslam.Config()
        floors.set("front_end.kind", "fused")
        floors.set("barometer.use_barometer", True)
        walker = ratslam.Session(floors)
        walker.pressure(1.0, 976.8)
        with self.assertRaisesRegex(ratslam.Error, "pressure at t=2.*outside"):
            walker.pressure(2.0, 5000.0)
        fabmap = ratslam.Config()
        fabmap.set("front_end.kind", "fabmap")
        with self.assertRaisesRegex(ratslam.Error, "FABMAP"):
            ratslam.Session(fabmap)


    def test_descriptors_saved_by_numpy_drive_the_descriptor_front_end(self):
        """Descriptors computed in NumPy (random Fourier features of the true position, whose
        cosine similarity is about exp(-d^2 / 2) for places d metres apart) replace the images:
        the folder keeps no image, numpy.save and numpy.savetxt files give the same map, and
        every match is a true re-visit."""
        data = os.path.join(self.root, "descriptor_data")
        os.makedirs(data, exist_ok=True)
        for name in os.listdir(self.data):
            if name.endswith(".csv") or name.endswith(".toml"):
                shutil.copy(os.path.join(self.data, name), data)
        images = read_csv(os.path.join(data, "images.csv"))
        truth = read_csv(os.path.join(data, "ground_truth.csv"))
        t = np.array([float(r["time_s"]) for r in images])
        gt_t = np.array([float(r["time_s"]) for r in truth])
        x = np.interp(t, gt_t, [float(r["x_m"]) for r in truth])
        y = np.interp(t, gt_t, [float(r["y_m"]) for r in truth])
        rng = np.random.default_rng(5)
        w = rng.normal(size=(2, 128))
        phase = rng.uniform(0, 2 * np.pi, size=128)
        descriptors = np.cos(np.outer(x, w[0]) + np.outer(y, w[1]) + phase)
        descriptors += 0.05 * rng.normal(size=descriptors.shape)
        np.save(os.path.join(data, "descriptors.npy"), np.asfortranarray(descriptors))
        np.savetxt(os.path.join(data, "descriptors.csv"), descriptors, delimiter=",")
        config = ratslam.Config.load(SYNTHETIC_CONFIG)
        config.set("front_end.kind", "descriptors")
        config.set("descriptors.min_similarity", 0.92)
        run = ratslam.replay([data], os.path.join(self.root, "descriptors_npy"), config=config)
        s = run["summary"]
        self.assertEqual(s["frames"], len(images))
        self.assertGreater(s["loop_closures"], 5)
        self.assertGreater(s["matches"], 100)
        self.assertGreaterEqual(s["match_rate_within_m"]["2"], 0.99)
        self.assertLess(s["map_ate_m"], 0.3 * s["odometry_ate_m"])
        config.set("descriptors.file", "descriptors.csv")
        from_csv = ratslam.replay([data], os.path.join(self.root, "descriptors_csv"), config=config)
        np.testing.assert_array_equal(from_csv["experiences"]["x_m"], run["experiences"]["x_m"])
        # Fed frame by frame (at equal times the frame before the odometry, as the replay).
        session = ratslam.Session(config)
        odometry = read_csv(os.path.join(data, "odometry.csv"))
        events = [(t[i], 0, i) for i in range(len(images))] + \
                 [(float(r["time_s"]), 1, r) for r in odometry]
        events.sort(key=lambda e: (e[0], e[1]))
        for time_s, kind, item in events:
            if kind == 0:
                session.descriptor(time_s, descriptors[item])
            else:
                session.odometry(time_s, float(item["forward_speed_m_per_s"]),
                                 float(item["turn_rate_rad_per_s"]))
        np.testing.assert_array_equal(session.experiences()["x_m"], run["experiences"]["x_m"])
        with self.assertRaisesRegex(ratslam.Error, "dimensions"):
            session.descriptor(events[-1][0] + 1.0, np.ones(3))
        # One row short: the error names the file and both counts.
        np.save(os.path.join(data, "short.npy"), descriptors[:-1].astype(np.float32))
        config.set("descriptors.file", "short.npy")
        with self.assertRaisesRegex(ratslam.Error, f"short.npy: {len(images) - 1} descriptors"):
            ratslam.replay([data], os.path.join(self.root, "descriptors_short"), config=config)

    def test_evaluate_equals_the_command_line(self):
        data = os.path.join(SOURCE, "..", "shared", "data", "msft-ilc20-site1")
        if not os.path.isdir(data):
            self.skipTest(f"missing {data}")
        config = os.path.join(SOURCE, "configs", "msft-ilc20-wifi.toml")
        cli = os.path.join(self.root, "evaluate_cli")
        subprocess.run([BINARY, "evaluate", "--quiet", "--config", config, "--map", data,
                        "--query", data, "--out", cli], check=True, capture_output=True)
        out = os.path.join(self.root, "evaluate_py")
        result = ratslam.evaluate(data, data, out, config=ratslam.Config.load(config))
        with open(os.path.join(cli, "evaluation.json")) as f:
            expected = json.load(f)
        got = result["evaluation"]
        for key in ("mode", "map_nodes", "queries", "correct_within_m", "misplaced_beyond_m",
                    "rejection_rate", "floor_mistake_rate", "by_map_distance",
                    "new_place_calibration", "baselines", "wifi_words"):
            self.assertEqual(got[key], expected[key], key)
        rows = read_csv(os.path.join(cli, "queries.csv"))
        np.testing.assert_array_equal(result["queries"]["match"],
                                      [int(r["match"]) if r["match"] else -1 for r in rows])
        np.testing.assert_array_equal(result["queries"]["x_m"], [float(r["x_m"]) for r in rows])
        np.testing.assert_array_equal(
            result["queries"]["best_mapped_log_odds"],
            [float(r["best_mapped_log_odds"]) if r["best_mapped_log_odds"] else -np.inf
             for r in rows])
        self.assertEqual(len(result["map"]["x_m"]), expected["map_nodes"])
        with self.assertRaisesRegex(ratslam.Error, "overwrite"):
            ratslam.evaluate(data, data, out, config=ratslam.Config.load(config))
        # Ctrl-C stops it between queries, with nothing half written.
        stopped = os.path.join(self.root, "evaluate_stopped")
        timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        with self.assertRaisesRegex(KeyboardInterrupt, "stopped"):
            ratslam.evaluate(data, data, stopped, config=ratslam.Config.load(config))
        timer.join()
        self.assertFalse(os.path.exists(os.path.join(stopped, "evaluation.json")))

    def test_locate_equals_the_command_line(self):
        walks = self.route22_walks("01", "03")
        wifi_map = os.path.join(self.root, "route22.wifimap")
        subprocess.run([BINARY, "wifi-map", "--data", walks[0], "--out", wifi_map], check=True,
                       capture_output=True)
        cli = os.path.join(self.root, "locate_cli")
        subprocess.run([BINARY, "locate", "--quiet", "--wifi-map", wifi_map, "--data", walks[1],
                        "--out", cli], check=True, capture_output=True)
        result = ratslam.locate(wifi_map, walks[1])
        with open(os.path.join(cli, "summary.json")) as f:
            expected = json.load(f)
        del expected["run"]
        self.assertEqual(result["summary"], expected)
        rows = read_csv(os.path.join(cli, "errors.csv"))
        scans = result["scans"]
        self.assertEqual(len(scans["time_s"]), expected["scans"])
        np.testing.assert_array_equal(scans["x_m"], [float(r["x_m"]) for r in rows])
        np.testing.assert_array_equal(scans["known_aps"], [int(r["known_aps"]) for r in rows])
        np.testing.assert_array_equal(
            scans["error_m"], [float(r["error_m"]) if r["error_m"] else np.nan for r in rows])
        self.assertEqual(int(np.sum(np.isfinite(scans["error_m"]))), expected["count"])
        with self.assertRaisesRegex(ratslam.Error, "no_such.wifimap"):
            ratslam.locate(os.path.join(self.root, "no_such.wifimap"), walks[1])


    def test_wifi_map_and_call_equal_the_command_line(self):
        walks = self.route22_walks("01", "03")
        run = os.path.join(self.root, "run")
        subprocess.run([BINARY, "replay", "--quiet", "--config",
                        os.path.join(SOURCE, "configs", "ipin2023-wifi-compass.toml"),
                        "--data", walks[0], "--out", run], check=True, capture_output=True)
        cli_map = os.path.join(self.root, "cli.wifimap")
        printed = subprocess.run([BINARY, "wifi-map", "--json", "--run", run, "--data", walks[0],
                                  "--out", cli_map], check=True, capture_output=True, text=True)
        expected = json.loads(printed.stdout)
        py_map = os.path.join(self.root, "py.wifimap")
        summary = ratslam.wifi_map([walks[0]], py_map, run=run)
        self.assertEqual(summary["wifi_map"], py_map)
        for key in ("wifi_map", "seconds", "run"):
            del expected[key]
            summary.pop(key, None)
        self.assertEqual(summary, expected)
        self.assertEqual(summary["positions_from"], "run trajectory")
        with open(cli_map, "rb") as a, open(py_map, "rb") as b:
            self.assertEqual(a.read(), b.read())
        with self.assertRaisesRegex(ratslam.Error, "overwrite=True"):
            ratslam.wifi_map([walks[0]], py_map)

        cli = os.path.join(self.root, "call_cli")
        subprocess.run([BINARY, "call", "--quiet", "--map", run, "--wifi-map", py_map, "--data",
                        walks[1], "--at", "100", "--out", cli], check=True, capture_output=True)
        called = ratslam.call(run, py_map, walks[1], 100)
        with open(os.path.join(cli, "call.json")) as f:
            expected = json.load(f)
        del expected["run"]
        self.assertEqual(called["call"], expected)
        rows = read_csv(os.path.join(cli, "route.csv"))
        route = called["route"]
        self.assertEqual(len(route["experience_id"]), expected["route_experiences"])
        np.testing.assert_array_equal(route["experience_id"],
                                      [int(r["experience_id"]) for r in rows])
        np.testing.assert_array_equal(route["x_m"], [float(r["x_m"]) for r in rows])
        np.testing.assert_array_equal(route["y_m"], [float(r["y_m"]) for r in rows])
        # The route starts where the robot is and passes every stop in order.
        self.assertEqual(route["experience_id"][0], expected["robot_experience"])
        stops = [e for e in route["experience_id"] if e in expected["stops"]]
        self.assertEqual(list(dict.fromkeys(stops)), expected["stops"])
        with self.assertRaisesRegex(ratslam.Error, "before at -5 s"):
            ratslam.call(run, py_map, walks[1], -5)


if __name__ == "__main__":
    unittest.main()
