"""The machine a generated page's figures were measured on (performance_report.py,
work_precision_page.py)."""
import platform


def cpu():
    """The CPU's model name from /proc/cpuinfo, else what platform knows."""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()
