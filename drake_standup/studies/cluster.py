"""Many independent simulations on a Dask cluster: a LocalCluster of single-threaded
worker processes on this machine, or the scheduler at an address. Used by the sweeps
(sweep.py) and the convergence study (convergence/)."""

from __future__ import annotations

import logging
import time


def open_client(workers: int, address: str | None):
    """A Dask client: on the scheduler at address, or on a LocalCluster of its own (closed
    with the client) of `workers` single-threaded worker processes on localhost only."""
    from distributed import Client

    if not address:
        return Client(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
    client = Client(address, timeout="30s")
    try:
        client.wait_for_workers(1, timeout=60)
    except TimeoutError:
        client.close()
        raise OSError(f"no Dask worker joined the scheduler at {address} in 60 s") from None
    return client


def run_on_cluster(
    tasks: list,
    on_result,
    *,
    workers: int,
    address: str | None,
    label: str,
    progress: bool = True,
) -> None:
    """Runs tasks [(item, key, fn, args), ...] on a Dask cluster (open_client)
    and, as each finishes, calls on_result(item, metrics, lost): metrics is
    fn's return value (a metrics dict) or None with lost the exception of a
    task the cluster lost (a dead worker: not the run's fault); on_result
    returns the metrics to count. A progress bar counts the runs, those not
    stood up and the rate; the cluster is closed however this ends."""
    from distributed import as_completed

    from drake_standup.sim.progress import ProgressBar

    client = open_client(workers, address)
    try:
        futures = {
            client.submit(fn, *args, key=key, pure=False): item for item, key, fn, args in tasks
        }
        bar = ProgressBar(len(tasks), label, unit="runs") if progress else None
        t0 = time.perf_counter()
        failed = 0
        for done, future in enumerate(as_completed(futures), start=1):
            item = futures[future]
            if future.status == "finished":
                metrics = on_result(item, future.result(), None)
            else:
                metrics = on_result(item, None, future.exception())
            failed += not metrics.get("success", False)
            future.release()
            if bar is not None:
                rate = 60.0 * done / (time.perf_counter() - t0)
                bar.update(done, f"{failed} not stood up; {rate:.1f} runs/min")
        if bar is not None:
            bar.close()
    finally:
        client.close()
