"""Device memory of the particle state and of the grid, per particle (the device suite's ``memory`` part)."""

from __future__ import annotations

__all__ = ["bytes_per_particle"]


def bytes_per_particle(device: str, quick: bool) -> dict:
    """Bytes per particle of the particle state and of the grid, elastic and Cam-Clay, 3D and 2D, on ``device``
    (about 2M particles each; ``quick``: 24 cells a side), and of the device pool on CUDA."""
    import warp as wp

    from .blocks import block_simulation

    rows = []
    wp.init()
    dev = wp.get_device(device)
    for dim, material in ((3, "elastic"), (3, "plastic"), (2, "elastic"), (2, "plastic")):
        n_grid = (24 if quick else 128) if dim == 3 else (24 if quick else 1448)
        wp.synchronize_device(dev)
        used0 = wp.get_mempool_used_mem_current(dev) if dev.is_cuda and wp.is_mempool_enabled(dev) else None
        sim = block_simulation(dim, material, n_grid, device, n_threads=1)
        N = sim.model.n_particles
        st = sim.stepper
        row = {"dim": dim, "material": material, "n_grid": n_grid, "n_particles": N,
               "particle_state_bytes_per_particle": sim.model.bytes_per_particle(sim.state),
               "grid_bytes_per_particle": (st.grid_m_all.capacity + st.grid_p_all.capacity) / N,
               "grid_nodes": int(st.grid_m.size), "grid_copies": st.n_threads}
        if used0 is not None:
            row["device_pool_bytes_per_particle"] = (wp.get_mempool_used_mem_current(dev) - used0) / N
        rows.append(row)
        del sim, st
    return {"device": device, "rows": rows,
            "note": "taichi's counts are in the throughput rows (bytes_per_particle, grid_bytes_per_particle)"}


