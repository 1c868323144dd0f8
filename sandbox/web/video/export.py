"""Folder « Vidéo » of the page: the last seconds of the simulation (the recording in
progress when there is one, else the states the session keeps: :mod:`sandbox.web.loop.rewind`)
as an MP4, made in the background and downloaded (issue 26's "Exporter une vidéo").

The video is drawn by :func:`sandbox.web.video.render.render_video` in a worker process at a
lowered priority (:mod:`sandbox.web.loop.background`), one video at a time
per server process: the other browsers keep their frames. The worker reads the recording
as written so far (a recording in progress is flushed every few seconds, and read as a
salvaged file), reports its progress in a small file, and writes the video to a
temporary folder; the page then downloads it. The pool stops when no video is waiting.
"""

from __future__ import annotations

import shutil
import tempfile
import threading
from concurrent.futures import Future
from pathlib import Path

import viser

from sandbox.errors import SandboxError
from sandbox.recording import load
from sandbox.web.client.text import plain
from sandbox.web.loop.background import BackgroundPool
from sandbox.web.loop.state import SessionState
from sandbox.web.video.aliasing import alias, turn_rate
from sandbox.web.video.options import VideoOptions

FOLDER = "Vidéo"
BUTTON = "Exporter une vidéo"
LAST = 20.0
"""Seconds of the recording the video shows (its end)."""
SIZE = (1280, 720)


def render_last(recording: str, out: str, progress: str, last: float = LAST) -> int:
    """In the worker: the last ``last`` seconds of ``recording`` (in progress) as the
    video ``out``; the frames done so far in ``progress`` (``done/total``)."""
    # Pillow and the video's drawing (15 MB a process) load only in the worker drawing it,
    # never in the server serving the pages
    from sandbox.web.video.render import render_video

    rec = load(Path(recording), salvage=True)
    options = VideoOptions(Path(out), size=SIZE, start=max(0.0, rec.duration - last))
    note = Path(progress)

    def say(done: int, total: int) -> None:
        if done % 10 == 0 or done == total:
            note.write_text(f"{done}/{total}", encoding="ascii")

    say(0, len(options.times(rec)))  # started: the page counts the frames from now
    return render_video(rec, options, say)


class VideoJobs:
    """The videos a server process makes, one at a time, in a low-priority process."""

    _shared: VideoJobs | None = None
    _lock = threading.Lock()

    def __init__(self) -> None:
        self._pool = BackgroundPool(1)
        self._waiting = 0
        self._mutex = threading.Lock()

    @classmethod
    def shared(cls) -> VideoJobs:
        """This process's queue of videos."""
        with cls._lock:
            if cls._shared is None:
                cls._shared = cls()
            return cls._shared

    def submit(self, recording: Path, out: Path, progress: Path) -> Future[int]:
        """Queue a video of ``recording``'s last seconds."""
        with self._mutex:
            self._waiting += 1
            future = self._pool.submit(render_last, str(recording), str(out), str(progress))
        future.add_done_callback(lambda _: self._finished())
        return future

    def _finished(self) -> None:
        with self._mutex:
            self._waiting -= 1
            if self._waiting == 0:
                self._pool.stop()


class VideoExport:
    """The folder: a button, a progress bar, what happens.

    Args:
        gui: A viser ``GuiApi``.
        controller: The live session (its recording in progress is what is exported).
    """

    def __init__(self, gui: viser.GuiApi, controller: SessionState) -> None:
        self.controller = controller
        self.client: viser.ClientHandle | None = None
        self.future: Future[int] | None = None
        self.folder_path: Path | None = None
        self._clicked: viser.ClientHandle | None = None
        self.hidden = ""  # what the video's frames hide, in French ("" when nothing)
        self._preparing = ""
        with gui.add_folder(FOLDER, expand_by_default=False) as self.folder:
            self.button = gui.add_button(
                BUTTON,
                hint=f"Les {LAST:.0f} dernières secondes, en vidéo MP4 pour vos diapositives "
                "(flèches, grandeurs clés, temps)",
            )
            self.progress = gui.add_progress_bar(0.0, visible=False)
            self.status = gui.add_markdown(
                f"Les {LAST:.0f} dernières secondes de la simulation (ou de l'enregistrement "
                "en cours), en MP4 pour vos diapositives."
            )
        self.button.on_click(lambda e: setattr(self, "_clicked", e.client))
        controller.on_close(self.close)

    def refresh(self) -> None:
        """From the session loop: start a video asked for; follow the one being made;
        download it when it is done."""
        client, self._clicked = self._clicked, None
        if client is not None and self.future is None:
            self._start(client)
        future = self.future
        if future is None or self.folder_path is None:
            return
        if not future.done():
            done, total = self._counts()
            self.progress.value = 100.0 * min(1.0, done / max(total, 1))  # type: ignore[misc]
            words = (
                f"{self._preparing} : image {done} sur {total}."
                if total
                else f"{self._preparing} : en attente d'un processeur libre (la classe passe "
                "d'abord)…"
            )
            if self.status.content != words:
                self.status.content = words
            return
        self.future = None
        self.progress.visible = False
        self.button.disabled = False
        folder, self.folder_path = self.folder_path, None
        try:
            frames = future.result()
            video = folder / "video.mp4"
            name = f"{self.controller.sim.label.replace('.', '_')}-video.mp4"
            if self.client is not None:
                self.client.send_file_download(name, video.read_bytes())
            self.status.content = (
                f"Vidéo prête ({frames} images, {frames / 30:.0f} s) : téléchargée sous {name}."
                + (f"  \n{plain(self.hidden, limit=600)}" if self.hidden else "")
            )
        except SandboxError as exc:  # e.g. no encoder here: the line names what to install
            self.status.content = f"La vidéo n'a pas pu être faite : {plain(str(exc))}"
        except Exception as exc:  # the worker failed: said once, the page goes on
            self.status.content = f"La vidéo n'a pas pu être faite ({type(exc).__name__})."
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    def _start(self, client: viser.ClientHandle) -> None:
        ctl = self.controller
        rec = ctl.recorder
        folder = Path(tempfile.mkdtemp(prefix="sandbox-video-"))
        if rec is not None and rec.frames >= 2:
            source, what = rec.path, "de l'enregistrement en cours"
        elif ctl.secret is not None:  # a challenge: the states hold the secret
            shutil.rmtree(folder, ignore_errors=True)
            self.status.content = "Pas de vidéo pendant un défi : elle montrerait le réglage caché."
            return
        else:
            source, what = folder / "last.sbx", "de la simulation"
            if not ctl.rewind.write(source, ctl.sim, ctl.lesson):
                shutil.rmtree(folder, ignore_errors=True)
                self.status.content = "Lancez la simulation (▶ Lecture), puis exportez."
                return
        self.client = client
        self.folder_path = folder
        with ctl.sim.lock:  # the rotation now, as the video will film it (speed ×1)
            rate = turn_rate(ctl.sim.model, ctl.sim.data.qvel)
        fps = VideoOptions(folder / "video.mp4").fps
        hidden = alias(rate, fps)
        self.hidden = hidden.french(fps) if hidden else ""
        self.future = VideoJobs.shared().submit(source, folder / "video.mp4", folder / "p.txt")
        self.progress.value = 0.0  # type: ignore[misc]
        self.progress.visible = True
        self.button.disabled = True
        self._preparing = f"Vidéo des {LAST:.0f} dernières secondes {what} en préparation"
        self.status.content = f"{self._preparing}…"

    def _counts(self) -> tuple[int, int]:
        """(frames made, frames to make); (0, 0) before the worker says."""
        note = self.folder_path / "p.txt" if self.folder_path is not None else None
        try:
            done, total = (note.read_text(encoding="ascii") if note else "0/0").split("/")
            return max(0, int(done)), max(0, int(total))
        except (OSError, ValueError):
            return 0, 0

    def close(self) -> None:
        """The browser left: the video being made is dropped, its folder removed once the
        worker is done with it."""
        future, folder = self.future, self.folder_path
        self.future = self.folder_path = None
        if folder is None:
            return
        if future is not None and not future.cancel() and not future.done():
            # running: the worker still writes there; removed when it ends
            future.add_done_callback(lambda _: shutil.rmtree(folder, ignore_errors=True))
            return
        shutil.rmtree(folder, ignore_errors=True)
