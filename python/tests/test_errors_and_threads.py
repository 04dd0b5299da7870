"""Bad input raises an exception naming the field; the engine runs with the GIL released; a
KeyboardInterrupt cancels a run; progress is reported."""

import _thread
import signal
import threading
import time

import pytest

pytest.importorskip("xarray", reason="xarray is not installed")
shoal = pytest.importorskip("shoal", reason="the shoal package is not installed: pip install ./python")


def test_bad_input_names_the_field():
    with pytest.raises(shoal.InputError, match="no_such_study"):
        shoal.study("no_such_study")
    with pytest.raises(shoal.InputError, match="aperture_mm: -5 is out of range"):
        shoal.simulate("lake_hume_bloom", "cubesat", decimation=16, settings={"instrument.aperture_mm": -5})
    with pytest.raises(shoal.InputError, match="instrument.no_such_field"):
        shoal.simulate("lake_hume_bloom", "cubesat", settings={"instrument.no_such_field": 1})
    with pytest.raises(shoal.InputError, match="decimation: 0 is out of range"):
        shoal.simulate("lake_hume_bloom", "cubesat", decimation=0)
    with pytest.raises(shoal.InputError) as e:
        shoal.study("cubesat_vs_smallsat", threads=100000)
    assert e.value.field == "threads"
    with pytest.raises(shoal.InputError, match="scene"):
        shoal.simulate("no_such_scene", "cubesat")
    # InputError is a ValueError: code that catches ValueError catches it.
    assert issubclass(shoal.InputError, ValueError)


def test_a_program_still_needs_the_users_yes():
    with pytest.raises(shoal.InputError, match="allow_external=True") as e:
        shoal.study("lake_hume_oc4", decimation=16)
    assert e.value.field == "retrievals"


def test_other_python_threads_run_while_the_engine_does():
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    shoal.study("cubesat_vs_smallsat", decimation=4)
    end = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # The counter ticks every ~1 ms when it has the GIL; held by the study it would not tick at all.
    assert end - start > 0.2 and len(during) > 0.2 * (end - start) * 1000, (len(during), end - start)


def test_keyboard_interrupt_cancels_the_run():
    # A process started in the background (`cmd &` in a script) inherits SIGINT ignored, and
    # Python then leaves it so: `interrupt_main` would do nothing. Ctrl-C's handler, as an
    # interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    start = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            shoal.study("cubesat_vs_smallsat")
    finally:
        signal.signal(signal.SIGINT, previous)
    # Full resolution takes tens of seconds; cancelled, it stops at its next row.
    assert time.perf_counter() - start < 10.0


def test_progress_reaches_the_end_in_order():
    seen = []
    shoal.study("cubesat_vs_smallsat", decimation=2, progress=seen.append)
    assert seen, "no progress reported"
    assert all(0.0 <= f <= 1.0 for f in seen)
    assert seen == sorted(seen)


def test_an_exception_in_the_progress_callback_stops_the_run():
    def fail(_):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        shoal.study("cubesat_vs_smallsat", progress=fail)
