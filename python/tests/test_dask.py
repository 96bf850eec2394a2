"""A study sharded over a Dask cluster and merged equals the single-process study, number for
number (the same code runs unchanged on a real cluster)."""

from __future__ import annotations

import pytest

import jitterid

distributed = pytest.importorskip("dask.distributed")


def run_shard(experiment, runs, seed, index, count):
    # Each worker runs its shard single-threaded: the cluster supplies the parallelism.
    return jitterid.montecarlo(experiment, runs=runs, seed=seed, shard=(index, count), threads=1)


def test_dask_sharded_study_equals_single_process(table2):
    runs, seed, count = 24, 7, 4
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        futures = [client.submit(run_shard, table2, runs, seed, i, count, pure=False) for i in range(count)]
        shards = client.gather(futures)
    merged = jitterid.merge(shards).to_dict()
    single = jitterid.montecarlo(table2, runs=runs, seed=seed).to_dict()
    merged.pop("seconds"), single.pop("seconds")
    assert merged == single
