"""weather_braking's recorder (a python_json engine): writes the car's camera as camera.mp4
(15 frames per simulated second, captioned with the time, the weather and the speed) and,
for each surface, one frame as frame_<surface>.png (the first at over 40 km/h) into the run
folder."""
import os

import cv2
import numpy as np
from convoy_video import VideoWriter
from nrp_core.engines.python_json import EngineScript

FPS = 15


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("observation")
        self._setDataPack("observation", {})
        self.dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.video = None
        self.saved = set()
        self.frames = 0

    def runLoop(self, timestep_ns):
        obs = self._getDataPack("observation")
        if not obs or "frame" not in obs:
            return
        frame = np.ascontiguousarray(np.asarray(obs["frame"], dtype=np.uint8)[:, :, ::-1])
        w = obs["weather"]
        speed = obs.get("speed", 0.0)
        surface = w.get("surface", "?")
        if surface not in self.saved and speed * 3.6 > 40:
            cv2.imwrite(os.path.join(self.dir, "frame_%s.png" % surface), frame)
            self.saved.add(surface)
        caption = "t %5.1f s  %s  %s %.1f  visibility %s  %3.0f km/h" % (
            self._time_ns * 1e-9, surface, w.get("precipitation_type", "none"),
            w.get("precipitation", 0.0),
            "%.0f m" % w["visibility_m"] if w.get("visibility_m", 1e9) < 5000 else "clear",
            speed * 3.6)
        cv2.rectangle(frame, (0, 0), (frame.shape[1], 24), (0, 0, 0), -1)
        cv2.putText(frame, caption, (6, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1,
                    cv2.LINE_AA)
        if self.video is None:
            self.video = VideoWriter(os.path.join(self.dir, "camera.mp4"), FPS)
        self.video.write(frame)
        self.frames += 1

    def shutdown(self):
        if self.video is not None:
            self.video.close()
            print("recorder: %d frames in camera.mp4" % self.frames, flush=True)
