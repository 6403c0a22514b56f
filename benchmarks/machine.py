"""What machine a benchmark ran on, for its figures (the house rule: give the CPU model with
every figure)."""

import subprocess


def cpu_model():
    """lscpu's model name, or "unknown"."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    except OSError:
        return "unknown"
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return "unknown"
