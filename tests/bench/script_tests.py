"""The tiny runner of the tools' test scripts (tests/bench/test_*.py, run by ctest without pytest's plugins):
every test_ function of a module, plus extra (name, function) pairs, each reported ok or FAIL with its
traceback; the exit status is 1 when any failed."""
import traceback


def run_tests(namespace, extra=()):
    tests = [(name, f) for name, f in namespace.items() if name.startswith("test_")] + list(extra)
    failed = 0
    for name, f in tests:
        try:
            f()
            print(f"ok   {name}")
        except Exception:
            failed += 1
            print(f"FAIL {name}")
            traceback.print_exc()
    print(f"{len(tests) - failed} passed, {failed} failed")
    return 1 if failed else 0
