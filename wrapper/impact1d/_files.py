"""Files written whole: under a temporary name beside the target, then renamed, so a full
disk or an interrupt leaves the previous file (or none), never a truncated one."""

import os


def write_whole(path, write) -> None:
    """Call write(temporary_path), then put that file in place as `path`."""
    root, ext = os.path.splitext(os.fspath(path))
    temporary = f"{root}.part{ext}"      # the extension still tells writers the format
    try:
        write(temporary)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise
