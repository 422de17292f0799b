"""FFmpeg's binary: reading what it says while we read its frames."""

import subprocess
import sys
import threading

from stabilize.video.binary import drain

# 5000 lines of 100 bytes on stderr (a damaged clip's decoding errors), then the frames
TALKATIVE = (
    "import sys\n"
    "for i in range(5000): sys.stderr.write(f'error {i:05d} ' + 'x' * 88 + '\\n')\n"
    "sys.stdout.write('frames')\n"
)


def test_a_child_that_says_much_never_blocks():
    child = subprocess.Popen(
        [sys.executable, "-c", TALKATIVE], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    said = drain(child.stderr, keep=3)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(child.stdout.read()), daemon=True)
    reader.start()
    reader.join(timeout=60)
    finished = not reader.is_alive()
    if not finished:
        child.kill()  # it blocked on a full pipe (500 kB, where a pipe holds 64 kB)
    child.wait()
    assert finished and got == [b"frames"]
    lines = said().splitlines()
    assert [line[:11] for line in lines] == [f"error {i:05d}" for i in (0, 1, 2, 4997, 4998, 4999)]
