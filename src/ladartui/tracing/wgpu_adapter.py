"""Which wgpu adapter the backend opens, and what to install when there is none."""

from __future__ import annotations

import os
import stat
import tempfile

INSTALL_HINT = (
    "no Vulkan, Metal or D3D12 adapter found: install Debian's mesa-vulkan-drivers (lavapipe) or a GPU driver"
)

ADAPTER_TYPE_RANK = {"DiscreteGPU": 0, "IntegratedGPU": 1, "VirtualGPU": 2, "CPU": 3}
# OpenGL adapters lack shader-f64 and large storage buffers; prefer the rest.
GRAPHICS_BACKEND_RANK = {"Vulkan": 0, "Metal": 0, "D3D12": 0, "OpenGL": 1}


def choose_adapter(adapters):
    """The adapter to use: discrete GPU, integrated GPU, virtual, then CPU.

    Among adapters of one type, Vulkan/Metal/D3D12 come before OpenGL.
    ``adapters`` are wgpu adapters (anything with ``.info`` mapping
    ``adapter_type`` and ``backend_type``); None when the list is empty.
    """

    def rank(indexed):
        position, adapter = indexed
        info = adapter.info
        return (
            ADAPTER_TYPE_RANK.get(info.get("adapter_type", ""), 4),
            GRAPHICS_BACKEND_RANK.get(info.get("backend_type", ""), 2),
            position,
        )

    if not adapters:
        return None
    return min(enumerate(adapters), key=rank)[1]


def give_driver_a_runtime_dir() -> None:
    """Set a private XDG_RUNTIME_DIR when there is no usable one.

    On headless machines Mesa's window-system probing prints "XDG_RUNTIME_DIR is
    invalid" straight to the process's stderr, which scribbles over the terminal
    UI. We never open a window, so any private folder satisfies it.
    """
    current = os.environ.get("XDG_RUNTIME_DIR")
    if current and os.path.isdir(current) and os.access(current, os.W_OK | os.X_OK):
        return
    folder = os.path.join(tempfile.gettempdir(), f"ladartui-runtime-{os.getuid()}")
    try:
        os.makedirs(folder, mode=0o700, exist_ok=True)
        info = os.lstat(folder)
        if info.st_uid != os.getuid() or not stat.S_ISDIR(info.st_mode):
            folder = tempfile.mkdtemp(prefix="ladartui-runtime-")
    except OSError:
        folder = tempfile.mkdtemp(prefix="ladartui-runtime-")
    os.environ["XDG_RUNTIME_DIR"] = folder
