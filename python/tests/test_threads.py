"""Two data sets refined from two Python threads at once give the reports each gives alone
(docs/python.md 4: the analysis keeps no state between calls). The data: the example's
training rows and its held-out rows (examples/data/compliance), whose reports differ."""
from __future__ import annotations

import threading

import dhcal
from conftest import EXAMPLE, columns


def test_two_threads_give_what_each_gives_alone():
    model = dhcal.load_model(EXAMPLE / "model.json")
    sets = [columns(EXAMPLE / name, model.n_joints) for name in ("train.csv", "heldout.csv")]

    def report(rows):
        return dhcal.refine(model, rows["q_deg"], rows["xyz_mm"]).report

    alone = [report(rows) for rows in sets]
    assert alone[0] != alone[1]
    assert all(len(r["steps"]) >= 2 for r in alone)  # the loop added an effect to each
    together = [None, None]

    def work(k):
        for _ in range(3):
            got = report(sets[k])
            if got != alone[k]:
                together[k] = got
                return
        together[k] = alone[k]

    threads = [threading.Thread(target=work, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert together == alone
