"""Reference counting: 1,000 short simulations from Python leave no memory behind (RSS), and a
simulator dies with its last reference."""

import gc
import sys
import weakref

import jelly


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def one_simulation(scene):
    sim = jelly.Simulator(scene)
    frames = []
    report = sim.run_until(0.01, callback=lambda s: frames.append(s.state.x.sum()))
    x, ks = sim.state.x, sim.model.springs.ks
    sim.state.v = sim.state.v * 0.5
    snapshot = sim.snapshot()
    sim.restore(snapshot)
    assert report.ok and len(frames) == 11 and x.shape == (125, 3) and ks.size
    return weakref.ref(sim)


def test_no_leak_over_1000_short_simulations(scenes):
    scene = jelly.load_scene(scenes / "drop_coulomb.json",
                             {"cube.n": 5, "output_interval": 0.001, "duration": 0.01})
    for _ in range(100):  # warm up allocators and caches
        one_simulation(scene)
    gc.collect()
    before = rss_bytes()
    for _ in range(1000):
        dead = one_simulation(scene)
        assert dead() is None  # freed at once by reference counting, no cycle
    gc.collect()
    growth = rss_bytes() - before
    # One leaked simulator of this size (125 particles, 1,500 springs, its arrays) is ~100 kB:
    # 1,000 of them would be ~100 MB.
    print(f"RSS growth over 1000 simulations: {growth / 1e6:.2f} MB")
    assert growth < 8e6


def test_callback_and_observers_release_their_references(scenes):
    scene = jelly.load_scene(scenes / "drop_coulomb.json", {"cube.n": 3})
    sim = jelly.Simulator(scene)

    def callback(s):
        pass

    refs = sys.getrefcount(sim), sys.getrefcount(callback)
    for _ in range(10):
        sim.run_until(sim.t + 0.02, callback=callback)
    assert (sys.getrefcount(sim), sys.getrefcount(callback)) == refs
