#!/usr/bin/env bash
# End-to-end tests of basalt-run's output layer (compute + I/O ranks). Usage:
#   io_e2e.sh CASE   with BASALT_RUN, MPIEXEC, SCENE, GEOMETRY, SCENE_OTHER, WORK set by CTest.
# Each case exits non-zero with a message when the behaviour is wrong.
set -u
case_name=$1
W=$WORK/$case_name
rm -rf "$W"
mkdir -p "$W"
# hwloc's GL probe would connect to an X server on :0 if one runs (and die with it): not wanted.
export HWLOC_COMPONENTS=-gl
CHECK="/usr/bin/python3 $(dirname "$0")/output_checks.py"
fail() { echo "FAIL ($case_name): $*"; exit 1; }

# run NP ARGS... : basalt-run on NP ranks with the test scene and geometry; output in $W/last.log
run() {
  local np=$1; shift
  "$MPIEXEC" -np "$np" "$BASALT_RUN" "$SCENE" --geometry "$GEOMETRY" --quiet "$@" >"$W/last.log" 2>&1
}
must_run() { run "$@" || { cat "$W/last.log"; fail "basalt-run $* exited non-zero"; }; }
must_fail() {  # must_fail REGEX NP ARGS...
  local regex=$1; shift
  if run "$@"; then cat "$W/last.log"; fail "basalt-run $* succeeded, expected an error"; fi
  grep -Eq -- "$regex" "$W/last.log" || { cat "$W/last.log"; fail "the error does not match /$regex/"; }
  cat "$W/last.log"
}

# Bit-for-bit restart: 200 steps straight vs 100 + restart + 100, on the same ranks.
restart_bitwise() {  # NP Q
  local np=$1 q=$2
  must_run "$np" --io-ranks "$q" --steps 200 --checkpoint-every 100 --output "$W/straight"
  must_run "$np" --io-ranks "$q" --steps 100 --checkpoint-every 100 --output "$W/split"
  must_run "$np" --io-ranks "$q" --steps 100 --checkpoint-every 100 --output "$W/split" --restart "$W/split"
  grep -q "continuing from step 100" "$W/last.log" || fail "the restart did not continue from step 100"
  $CHECK same "$W/straight/ckpt_000200.h5" "$W/split/ckpt_000200.h5" || fail "final checkpoints differ"
  cmp "$W/straight/ckpt_000200.h5" "$W/split/ckpt_000200.h5" || fail "final checkpoint files differ in their bytes"
  cmp "$W/straight/fields.csv" "$W/split/fields.csv" || fail "fields.csv differs (restart appends after step 100)"
  echo "np $np, --io-ranks $q: step-200 checkpoints identical (datasets and bytes), fields.csv identical"
}

case $case_name in
  restart_np1_q0) restart_bitwise 1 0 ;;
  restart_np2_q0) restart_bitwise 2 0 ;;
  restart_np1_q1) restart_bitwise 2 1 ;;
  restart_np2_q1) restart_bitwise 3 1 ;;
  restart_old_lists)
    # A skin so small that the lists are rebuilt every few steps (migrating particles at np 2), but
    # not at step 100: the checkpoint's lists date from an earlier step, which the restart replays.
    sed 's/^skin = .*/skin = 0.005/' "$SCENE" >"$W/small_skin.toml"
    grep -q '^skin = 0.005' "$W/small_skin.toml" || fail "could not set the skin in $W/small_skin.toml"
    SCENE=$W/small_skin.toml
    restart_bitwise 1 0
    $CHECK old_lists "$W/split/ckpt_000100.h5" || fail "np 1: the lists were rebuilt at the checkpoint step"
    rm -rf "$W/straight" "$W/split"
    restart_bitwise 3 1
    $CHECK old_lists "$W/split/ckpt_000100.h5" || fail "np 2: the lists were rebuilt at the checkpoint step"
    ;;
  restart_migration)
    # Particles change rank between rebuilds (a stronger wall pulse, 3 ranks stacked along z): the
    # replayed rebuild must give each particle the owner the uninterrupted run's migration gave it.
    sed -e 's/^skin = .*/skin = 0.005/' -e 's/amplitude = 0.1,/amplitude = 0.5,/' "$SCENE" >"$W/migrate.toml"
    grep -q 'amplitude = 0.5,' "$W/migrate.toml" || fail "could not set the amplitude in $W/migrate.toml"
    SCENE=$W/migrate.toml
    export BASALT_DEBUG_REBUILD=1
    must_run 3 --dims 1,1,3 --steps 300 --checkpoint-every 150 --output "$W/straight"
    # Owned counts of rank 0 at its rebuilds up to step 150: they must change (particles migrated).
    counts=$(grep '^rank 0 rebuild' "$W/last.log" | awk '$6 < 150 {print $8}' | sort -u | wc -l)
    [ "$counts" -gt 1 ] || fail "no particle migrated before the checkpoint: the case tests nothing"
    unset BASALT_DEBUG_REBUILD
    must_run 3 --dims 1,1,3 --steps 150 --checkpoint-every 150 --output "$W/split"
    $CHECK old_lists "$W/split/ckpt_000150.h5" || fail "the lists were rebuilt at the checkpoint step"
    must_run 3 --dims 1,1,3 --steps 150 --checkpoint-every 150 --output "$W/split" --restart "$W/split"
    $CHECK same "$W/straight/ckpt_000300.h5" "$W/split/ckpt_000300.h5" || fail "final checkpoints differ"
    cmp "$W/straight/ckpt_000300.h5" "$W/split/ckpt_000300.h5" || fail "final checkpoint files differ in their bytes"
    echo "np 3 (1x1x3), migration before the checkpoint: step-300 checkpoints identical"
    ;;
  restart_history)
    # Contacts with history (the test model test_contact_age: stiffness grows with the steps in
    # contact) while particles migrate (1x1x3, stronger pulse): the checkpoint stores every contact's
    # age (/contacts), the restart gives each back to its pair, and the continuation is bit for bit.
    sed -e 's/^skin = .*/skin = 0.005/' -e 's/amplitude = 0.1,/amplitude = 0.5,/' \
        -e 's/^type = "linear_elastic"/type = "test_contact_age"\ngrowth = 0.5\nsaturation = 20/' "$SCENE" >"$W/history.toml"
    grep -q '^type = "test_contact_age"' "$W/history.toml" || fail "could not set the contact model in $W/history.toml"
    SCENE=$W/history.toml
    must_run 3 --dims 1,1,3 --steps 300 --checkpoint-every 150 --output "$W/straight"
    grep -q "contact history: test_contact_age 8 B per contact" "$W/last.log" || fail "the fields line does not show the contact history"
    must_run 3 --dims 1,1,3 --steps 150 --checkpoint-every 150 --output "$W/split"
    $CHECK contacts "$W/split/ckpt_000150.h5" 100 || fail "the step-150 checkpoint holds too few aged contacts"
    must_run 3 --dims 1,1,3 --steps 150 --checkpoint-every 150 --output "$W/split" --restart "$W/split"
    $CHECK same "$W/straight/ckpt_000300.h5" "$W/split/ckpt_000300.h5" || fail "final checkpoints differ"
    cmp "$W/straight/ckpt_000300.h5" "$W/split/ckpt_000300.h5" || fail "final checkpoint files differ in their bytes"
    echo "np 3 (1x1x3), aging contacts and migration: step-300 checkpoints identical"
    ;;
  restart_old_checkpoint)
    # A checkpoint without the positions at the last rebuild (older basalt-run): the restart warns
    # and rebuilds plainly; the continuation agrees to rounding.
    must_run 2 --steps 200 --checkpoint-every 100 --output "$W/straight"
    must_run 2 --steps 100 --checkpoint-every 100 --output "$W/old"
    $CHECK strip_rebuild "$W/old/ckpt_000100.h5" || fail "could not strip the checkpoint"
    must_run 2 --steps 100 --checkpoint-every 100 --output "$W/old" --restart "$W/old/ckpt_000100.h5"
    grep -q "has no /particles/position_at_rebuild" "$W/last.log" || fail "no warning about the old checkpoint"
    $CHECK close "$W/straight/ckpt_000200.h5" "$W/old/ckpt_000200.h5" 1e-9 || fail "the continuation drifted"
    ;;
  restart_break_at_checkpoint)
    # Bonds that break at the checkpoint's own step while their spheres still overlap: 20 vertical
    # pairs (rest length = initial distance 0.99 (r1 + r2), break strain 0.001) on the base wall,
    # kicked by a stronger pulse; all break at step 194 (the check below proves one did, overlapping).
    # The restart must not apply the contact force the uninterrupted run could not yet see.
    {
      echo "LSMGeometry 1.2"; echo "BoundingBox 0 0 0 40 1 2"; echo "PeriodicBoundaries 0 0 0"
      echo "Dimension 3D"; echo "BeginParticles"; echo "Simple"; echo 40
      for k in $(seq 0 19); do
        echo "$((2 * k)).5 0.5 0.5 0.5 $((2 * k)) 1"
        echo "$((2 * k)).5 0.5 1.49 0.5 $((2 * k + 1)) 1"
      done
      echo "EndParticles"; echo "BeginConnect"; echo 20
      for k in $(seq 0 19); do echo "$((2 * k)) $((2 * k + 1)) 0"; done
      echo "EndConnect"
    } >"$W/pairs.geo"
    sed -e 's/^rest_length = .*/&\nbreak_strain = 0.001/' -e 's/amplitude = 0.1,/amplitude = 2.0,/' "$SCENE" >"$W/break.toml"
    grep -q '^break_strain = 0.001' "$W/break.toml" && grep -q 'amplitude = 2.0,' "$W/break.toml" ||
      fail "could not set the break strain and amplitude in $W/break.toml"
    SCENE=$W/break.toml GEOMETRY=$W/pairs.geo
    for np in 1 2; do
      rm -rf "$W/straight" "$W/split"
      must_run $np --steps 388 --checkpoint-every 194 --output "$W/straight"
      $CHECK break_overlap "$W/straight/ckpt_000194.h5" || fail "no bond broke at the checkpoint step: the case tests nothing"
      must_run $np --steps 194 --checkpoint-every 194 --output "$W/split"
      must_run $np --steps 194 --checkpoint-every 194 --output "$W/split" --restart "$W/split"
      $CHECK same "$W/straight/ckpt_000388.h5" "$W/split/ckpt_000388.h5" || fail "np $np: final checkpoints differ"
      cmp "$W/straight/ckpt_000388.h5" "$W/split/ckpt_000388.h5" || fail "np $np: final checkpoint files differ"
      echo "np $np: bonds broken at the checkpoint step, step-388 checkpoints identical"
    done
    ;;
  restart_other_ranks)
    must_run 2 --steps 200 --checkpoint-every 100 --output "$W/straight"
    must_run 2 --steps 100 --checkpoint-every 100 --output "$W/a"
    cp -r "$W/a" "$W/b"
    must_run 1 --steps 100 --checkpoint-every 100 --output "$W/a" --restart "$W/a/ckpt_000100.h5"
    must_run 4 --io-ranks 1 --steps 100 --checkpoint-every 100 --output "$W/b" --restart "$W/b"
    $CHECK close "$W/straight/ckpt_000200.h5" "$W/a/ckpt_000200.h5" 1e-9 || fail "np 2 -> 1 drifted"
    $CHECK close "$W/straight/ckpt_000200.h5" "$W/b/ckpt_000200.h5" 1e-9 || fail "np 2 -> 3+1 drifted"
    ;;
  restart_np3_to_np2)
    # A 3-rank run continued on 2 ranks (+ 1 I/O rank): energies and state within 1e-9 of the 3-rank run.
    must_run 3 --steps 200 --checkpoint-every 100 --fields-every 1 --output "$W/straight"
    must_run 3 --steps 100 --checkpoint-every 100 --fields-every 1 --output "$W/split"
    must_run 3 --io-ranks 1 --steps 100 --checkpoint-every 100 --fields-every 1 --output "$W/split" --restart "$W/split"
    grep -q "on 2 compute rank" "$W/last.log" || fail "the restart did not run on 2 compute ranks"
    $CHECK close "$W/straight/ckpt_000200.h5" "$W/split/ckpt_000200.h5" 1e-9 || fail "np 3 -> 2+1 drifted"
    /usr/bin/python3 - "$W/straight/fields.csv" "$W/split/fields.csv" <<'PY' || fail "np 3 -> 2+1: energies differ by more than 1e-9"
import sys
rows = [[l.split(",") for l in open(f).read().split()[1:]] for f in sys.argv[1:]]
assert len(rows[0]) == len(rows[1]) == 200, [len(r) for r in rows]
scale = max(abs(float(r[2])) for r in rows[0])
worst = max(abs(float(a[2]) - float(b[2])) / scale for a, b in zip(*rows) if a[0] == b[0])
assert all(a[0] == b[0] for a, b in zip(*rows))
print(f"kinetic energy over 200 steps: largest difference {worst:.3g} of the largest value")
assert worst <= 1e-9
PY
    ;;
  fields_q0_q1)
    must_run 2 --io-ranks 0 --steps 150 --fields-every 1 --output "$W/q0"
    must_run 3 --io-ranks 1 --steps 150 --fields-every 1 --output "$W/q1"
    [ "$(wc -l <"$W/q0/fields.csv")" -eq 151 ] || fail "expected a header and 150 rows"
    cmp "$W/q0/fields.csv" "$W/q1/fields.csv" || fail "fields.csv differs between --io-ranks 0 and 1"
    ;;
  vtk_frames)
    must_run 3 --io-ranks 1 --steps 100 --checkpoint-every 50 --frames-every 25 --output "$W/out"
    [ "$(grep -c '<DataSet' "$W/out/frames.pvd")" -eq 4 ] || fail "expected 4 frames in frames.pvd"
    $CHECK pvd "$W/out" || fail "VTK frames disagree with the checkpoints"
    grep -Eq "frames +4 files" "$W/last.log" || fail "the report does not count 4 frames"
    # A restart from step 50 in the same folder: the series drops the frames after it and continues;
    # fields.csv keeps its rows up to step 50 and appends, with no step twice.
    must_run 3 --io-ranks 1 --steps 50 --checkpoint-every 50 --frames-every 25 --output "$W/out" \
      --restart "$W/out/ckpt_000050.h5"
    [ "$(grep -c '<DataSet' "$W/out/frames.pvd")" -eq 4 ] || fail "frames.pvd after the restart: expected 4 frames"
    [ -z "$(cut -d, -f1 "$W/out/fields.csv" | sort | uniq -d)" ] || fail "fields.csv has a step twice"
    [ "$(wc -l <"$W/out/fields.csv")" -eq 101 ] || fail "fields.csv: expected a header and 100 rows"
    $CHECK pvd "$W/out" || fail "VTK frames disagree with the checkpoints after the restart"
    ;;
  xdmf)
    # ParaView opens the checkpoints as they are: ckpt_<step>.xmf beside each, ckpt_series.xmf for all,
    # with Q = 1 and Q = 0; after a restart from step 50 the series lists only the new run's history.
    for q in 1 0; do
      must_run $((2 + q)) --io-ranks $q --steps 100 --checkpoint-every 25 --output "$W/q$q"
      $CHECK xdmf "$W/q$q" 25,50,75,100 || fail "--io-ranks $q: the XDMF descriptions are wrong"
    done
    must_run 3 --io-ranks 1 --steps 25 --checkpoint-every 25 --output "$W/q1" --restart "$W/q1/ckpt_000050.h5"
    $CHECK xdmf "$W/q1" 25,50,75 || fail "after a restart from step 50 to 75: the series is wrong"
    ;;
  compressed)
    # output.compression = "fast" | "small": smaller checkpoints, shuffle + deflate on the big datasets,
    # the same values as an uncompressed run, and a restart from a compressed checkpoint bit for bit.
    must_run 3 --io-ranks 1 --steps 100 --checkpoint-every 100 --output "$W/none"
    scene0=$SCENE
    for level in fast small; do
      sed "s/^\[output\]\$/[output]\ncompression = \"$level\"/" "$scene0" >"$W/$level.toml"
      grep -q "^compression = \"$level\"" "$W/$level.toml" || fail "could not set the compression in $W/$level.toml"
      SCENE=$W/$level.toml
      rm -rf "$W/straight" "$W/split"
      restart_bitwise 3 1
      $CHECK compressed "$W/split/ckpt_000200.h5" || fail "$level: the checkpoint is not compressed"
      must_run 1 --steps 100 --checkpoint-every 100 --output "$W/q0_$level"
      $CHECK compressed "$W/q0_$level/ckpt_000100.h5" || fail "$level, Q = 0: the checkpoint is not compressed"
      $CHECK same "$W/none/ckpt_000100.h5" "$W/split/ckpt_000100.h5" || fail "$level: values differ from the uncompressed run"
      none_size=$(stat -c %s "$W/none/ckpt_000100.h5")
      size=$(stat -c %s "$W/split/ckpt_000100.h5")
      echo "$level: $size bytes against $none_size uncompressed"
      [ "$size" -lt $((none_size * 3 / 4)) ] || fail "$level: $size bytes is not smaller than 3/4 of $none_size"
    done
    sed 's/^\[output\]$/[output]\ncompression = "zip"/' "$scene0" >"$W/bad.toml"
    SCENE=$W/bad.toml
    must_fail "compression" 1 --steps 10 --output "$W/bad"
    ;;
  two_io_ranks)
    # 2 compute + 2 I/O ranks: one checkpoint file per step (I/O rank 0 gathers), one VTK piece per I/O
    # rank; the checkpoints equal those of 2 compute ranks writing themselves.
    must_run 4 --io-ranks 2 --steps 100 --checkpoint-every 50 --frames-every 50 --output "$W/q2"
    must_run 2 --io-ranks 0 --steps 100 --checkpoint-every 50 --output "$W/q0"
    [ -e "$W/q2/frame_00000100/piece_0001.vtp" ] || fail "no VTK piece from the second I/O rank"
    $CHECK same "$W/q2/ckpt_000100.h5" "$W/q0/ckpt_000100.h5" || fail "checkpoints differ between Q = 2 and Q = 0"
    $CHECK pvd "$W/q2" || fail "VTK frames disagree with the checkpoints"
    ;;
  unwritable_output)
    touch "$W/a_file"
    must_fail "$W/a_file/out: cannot create the output folder" 3 --io-ranks 1 --steps 10 --output "$W/a_file/out"
    must_fail "$W/a_file/out: cannot create the output folder" 1 --steps 10 --output "$W/a_file/out"
    ;;
  disk_full)
    # A 1 MB file-size limit on the ranks (not on mpirun, whose PMIx needs its shared-memory files): a
    # checkpoint (~1.6 MB) fails with EFBIG (SIGXFSZ is ignored) and the error names the file; no
    # checkpoint is left under its final name; the run stops non-zero at the same step on all ranks.
    for q in 0 1; do
      np=$((1 + q))
      "$MPIEXEC" -np $np bash -c "ulimit -f 1000; exec \"$BASALT_RUN\" \"$SCENE\" --geometry \"$GEOMETRY\" --quiet --io-ranks $q --steps 100 --checkpoint-every 50 --output \"$W/q$q\"" >"$W/last.log" 2>&1
      code=$?
      cat "$W/last.log"
      [ $code -ne 0 ] || fail "--io-ranks $q: the run succeeded although the disk was full"
      grep -Eq "$W/q$q/ckpt_000050.h5" "$W/last.log" || fail "--io-ranks $q: the error does not name the checkpoint"
      grep -q "error: output failed" "$W/last.log" || fail "--io-ranks $q: no clean stop"
      [ ! -e "$W/q$q/ckpt_000050.h5" ] || fail "--io-ranks $q: a failed checkpoint is left under its final name"
    done
    # on_error = "continue": the run goes on without checkpoints and exits 0, reporting the failure.
    sed 's/^\[output\]$/[output]\non_error = "continue"/' "$SCENE" >"$W/continue.toml"
    "$MPIEXEC" -np 2 bash -c "ulimit -f 1000; exec \"$BASALT_RUN\" \"$W/continue.toml\" --geometry \"$GEOMETRY\" \
        --quiet --io-ranks 1 --steps 100 --checkpoint-every 50 --output \"$W/cont\"" >"$W/last.log" 2>&1
    code=$?
    cat "$W/last.log"
    [ $code -eq 0 ] || fail "on_error = continue: the run stopped"
    grep -q "done: 100 steps" "$W/last.log" || fail "on_error = continue: the run did not finish"
    grep -q "ckpt_000050.h5" "$W/last.log" || fail "on_error = continue: the failure is not reported"
    ;;
  killed_mid_checkpoint)
    # Slow storage (throttled I/O rank), checkpoints every 20 steps; SIGKILL the ranks once two
    # checkpoints exist, plant a cut-off newer checkpoint and a .partial: --restart DIR must take the
    # last complete one.
    "$MPIEXEC" -np 2 "$BASALT_RUN" "$SCENE" --geometry "$GEOMETRY" --quiet --io-ranks 1 --steps 100000 \
      --checkpoint-every 20 --throttle-io-mbps 4 --output "$W/out" >"$W/killed.log" 2>&1 &
    mpirun_pid=$!
    for _ in $(seq 1 600); do
      [ "$(ls "$W/out"/ckpt_*.h5 2>/dev/null | wc -l)" -ge 2 ] && break
      sleep 0.1
    done
    for pid in $(pgrep -P "$mpirun_pid"); do kill -9 "$pid"; done
    kill -9 "$mpirun_pid" 2>/dev/null
    wait "$mpirun_pid" 2>/dev/null
    last=$(ls "$W/out"/ckpt_*.h5 | sort | tail -1)
    [ -n "$last" ] || fail "no checkpoint written before the kill"
    $CHECK complete "$last" || fail "$last is incomplete"
    head -c 100000 "$last" >"$W/out/ckpt_999999.h5"
    cp "$last" "$W/out/ckpt_999990.h5.partial"
    must_run 2 --io-ranks 1 --steps 20 --checkpoint-every 20 --output "$W/out" --restart "$W/out"
    step=$(basename "$last" .h5 | sed 's/ckpt_0*//')
    grep -q "continuing from step $step ($last)" "$W/last.log" || { cat "$W/last.log"; fail "did not restart from $last"; }
    # The fallback is said, naming the checkpoint passed over and the one taken (issue 16).
    grep -q "warning: --restart $W/out: ckpt_999999.h5 not complete .*continuing from the newest complete checkpoint, $last" \
      "$W/last.log" || { cat "$W/last.log"; fail "the fallback past the cut-off checkpoint is not said"; }
    must_fail "ckpt_999999.h5" 2 --io-ranks 1 --steps 20 --output "$W/out2" --restart "$W/out/ckpt_999999.h5"
    ;;
  killed_fields_complete)
    # SIGKILL right after the first checkpoint appears (Q = 1 and Q = 0): fields.csv must already hold
    # every row up to its step. Compute ranks send rows in batches of 256, so before the rows were
    # handed over ahead of each checkpoint, a run killed after ckpt_000050 had none of them on disk and
    # a restart from it left a silent gap (found by tools/soak/soak.py).
    for q in 1 0; do
      out="$W/out_q$q"
      "$MPIEXEC" -np $((1 + q)) "$BASALT_RUN" "$SCENE" --geometry "$GEOMETRY" --quiet --io-ranks $q \
        --steps 100000 --checkpoint-every 50 --output "$out" >"$W/killed_q$q.log" 2>&1 &
      mpirun_pid=$!
      for _ in $(seq 1 3000); do
        [ -e "$out/ckpt_000050.h5" ] && break
        sleep 0.01
      done
      for pid in $(pgrep -P "$mpirun_pid"); do kill -9 "$pid"; done
      kill -9 "$mpirun_pid" 2>/dev/null
      wait "$mpirun_pid" 2>/dev/null
      [ -e "$out/ckpt_000050.h5" ] || fail "Q = $q: no checkpoint before the kill"
      rows=$(awk -F, 'NR > 1 && $1 <= 50' "$out/fields.csv" | wc -l)
      [ "$rows" -eq 50 ] || fail "Q = $q: fields.csv holds $rows of the 50 rows up to the checkpoint's step 50"
      # The restart from it appends with no gap and no duplicate.
      must_run $((1 + q)) --io-ranks $q --steps 10 --output "$out" --restart "$out/ckpt_000050.h5"
      steps=$(awk -F, 'NR > 1 {print $1}' "$out/fields.csv" | sort -n | uniq | wc -l)
      total=$(awk -F, 'NR > 1' "$out/fields.csv" | wc -l)
      [ "$steps" -eq 60 ] && [ "$total" -eq 60 ] || fail "Q = $q: after the restart fields.csv has $total rows, $steps steps (60 expected)"
    done
    ;;
  folder_removed)
    # The output folder disappears mid-run: the next checkpoint fails naming its path, the run stops
    # cleanly (exit 1, I/O rank released); a checkpoint completed elsewhere before stays restartable.
    "$MPIEXEC" -np 2 "$BASALT_RUN" "$SCENE" --geometry "$GEOMETRY" --quiet --io-ranks 1 --steps 3000 \
      --checkpoint-every 20 --throttle-io-mbps 8 --output "$W/out" >"$W/last.log" 2>&1 &
    mpirun_pid=$!
    for _ in $(seq 1 600); do
      [ -e "$W/out/ckpt_000020.h5" ] && break
      sleep 0.1
    done
    mkdir -p "$W/kept" && cp "$W/out/ckpt_000020.h5" "$W/kept/"
    # Gone at once: renamed, then removed (an rm -rf alone raced the I/O rank's next file and could leave the
    # folder in place: "Directory not empty", and the run went on).
    mv "$W/out" "$W/out.removed"
    rm -rf "$W/out.removed" || true
    wait "$mpirun_pid"
    code=$?
    cat "$W/last.log"
    [ $code -ne 0 ] || fail "the run succeeded although its output folder was removed"
    grep -Eq "error: output failed.*$W/out/" "$W/last.log" || fail "the error does not name a path in the removed folder"
    must_run 1 --steps 10 --output "$W/again" --restart "$W/kept"
    ;;
  other_scene)
    must_run 1 --steps 20 --checkpoint-every 20 --output "$W/out"
    if "$MPIEXEC" -np 1 "$BASALT_RUN" "$SCENE_OTHER" --geometry "$GEOMETRY" --quiet --steps 10 --output "$W/o2" \
         --restart "$W/out/ckpt_000020.h5" >"$W/last.log" 2>&1; then
      fail "a checkpoint of another scene was accepted"
    fi
    cat "$W/last.log"
    grep -q "ckpt_000020.h5: this checkpoint was written by another scene" "$W/last.log" || fail "unclear error"
    must_fail "--restart .*nothing_here: no such file" 1 --steps 10 --output "$W/o3" --restart "$W/nothing_here"
    mkdir -p "$W/empty"
    must_fail "--restart .*empty: no complete checkpoint" 1 --steps 10 --output "$W/o3" --restart "$W/empty"
    ;;
  pictures)
    # In-situ pictures (issue 15): I/O rank 0 draws a PNG every 50 steps (a frame only for the picture at
    # 50 and 150, with the checkpoints at 100 and 200), on 2 compute ranks + 1 I/O rank, then on 2 + 2
    # (I/O rank 1 hands its compute rank's particles to I/O rank 0). Each step asked for has its PNG or
    # is in the report's skipped list; each PNG is not blank and shows both ends of the colour map; the
    # checkpoints equal a run's without pictures (pictures never change the physics).
    spec="color=velocity_z,cut=y,view=-y,size=320x240"
    must_run 2 --steps 200 --checkpoint-every 100 --output "$W/plain"
    for q in 1 2; do
      must_run $((2 + q)) --io-ranks $q --steps 200 --checkpoint-every 100 --render-every 50 --render "$spec" \
        --output "$W/q$q"
      cat "$W/last.log"
      $CHECK pictures "$W/q$q" 50,100,150,200 "$W/last.log" 320x240 || fail "--io-ranks $q: pictures wrong"
      $CHECK same "$W/plain/ckpt_000200.h5" "$W/q$q/ckpt_000200.h5" || fail "--io-ranks $q: pictures changed the run"
    done
    # The same from the scene's keys.
    sed 's|^\[output\]|[output]\nrender_every = 100\nrender = "color=speed,size=200x150"|' "$SCENE" >"$W/scene.toml"
    SCENE=$W/scene.toml must_run 3 --io-ranks 1 --steps 200 --output "$W/keys"
    $CHECK pictures "$W/keys" 100,200 "$W/last.log" 200x150 || fail "output.render_every: pictures wrong"
    ;;
  pictures_skipped)
    # Pictures asked for faster than the I/O rank draws them (every step): the run is not held up, the
    # pictures that cannot keep up are skipped and counted, and the report lists them; the count of PNGs
    # still equals the steps asked for less those skipped. (Both ends of the colour map are not asked of
    # these pictures: at steps 1-2 only a few spheres on the base move; the case "pictures" checks them.)
    steps=$(seq -s, 1 60)
    must_run 3 --io-ranks 1 --steps 60 --render-every 1 --render "size=160x120" --output "$W/out"
    cat "$W/last.log"
    $CHECK pictures "$W/out" "$steps" "$W/last.log" 160x120 any || fail "the pictures and the report disagree"
    grep -Eq "pictures .* [1-9][0-9]* skipped \(steps .*a newer frame came" "$W/last.log" || fail "no picture was skipped"
    grep -q "basalt-run: picture of step [0-9]* skipped" "$W/last.log" || fail "the skips were not logged as they happened"
    wait_s=$(sed -nE 's/.*compute ranks waited ([0-9.]+) s for output.*/\1/p' "$W/last.log")
    awk -v w="$wait_s" 'BEGIN { exit !(w < 1.0) }' || fail "the compute ranks waited $wait_s s for output"
    ;;
  pictures_bad_input)
    # A bad spec names the key (command line and scene); pictures without an I/O rank are refused; an
    # unknown field stops the run at the first picture, naming the field and what is available.
    must_fail '--render "colr=velocity_z": unknown key "colr" \(keys: color, cut, view, range, size\)' 2 \
      --io-ranks 1 --steps 10 --render-every 5 --render "colr=velocity_z" --output "$W/o"
    must_fail '--render cut "w": expected x, y or z' 2 --io-ranks 1 --steps 10 --render-every 5 --render "cut=w" --output "$W/o"
    must_fail '--render size "12": expected WIDTHxHEIGHT' 2 --io-ranks 1 --steps 10 --render-every 5 --render "size=12" --output "$W/o"
    must_fail '--render: no pictures asked for: give --render-every' 2 --io-ranks 1 --steps 10 --render "cut=y" --output "$W/o"
    must_fail '--render-every 5: in-situ pictures need an I/O rank \(--io-ranks 1 or more\)' 1 --steps 10 --render-every 5 --output "$W/o"
    sed 's|^\[output\]|[output]\nrender_every = 5\nrender = "view=+w"|' "$SCENE" >"$W/bad.toml"
    SCENE=$W/bad.toml must_fail 'bad.toml:[0-9]+: output.render: view "\+w": expected \+x' 2 --io-ranks 1 --steps 10 --output "$W/o"
    sed 's|^\[output\]|[output]\nrender_every = 5|' "$SCENE" >"$W/q0.toml"
    SCENE=$W/q0.toml must_fail 'output.render_every 5: in-situ pictures need an I/O rank' 1 --steps 10 --output "$W/o"
    must_fail 'picture of step 5: render "color=spin": unknown colour field "spin"; available: .*velocity_z' 2 \
      --io-ranks 1 --steps 10 --render-every 5 --render "color=spin" --output "$W/o"
    ;;
  pictures_on_demand)
    # A run without pictures neither links nor loads VTK's rendering: basalt-run has no OpenGL, X or VTK
    # rendering library among its dependencies, and runs with the render module made unloadable; with
    # pictures, that module is what fails, named.
    if ldd "$BASALT_RUN" | grep -Ei 'libvtkRendering|libGL|libX11|libvtkInteraction'; then
      fail "basalt-run links rendering libraries (above)"
    fi
    ldd "$(dirname "$BASALT_RUN")/basalt-render-insitu.so" | grep -q libvtkRenderingOpenGL2 || fail "the module does not link VTK's OpenGL rendering"
    export BASALT_RENDER_MODULE=$W/no-such-module.so
    must_run 2 --io-ranks 1 --steps 20 --checkpoint-every 10 --output "$W/plain"
    must_fail "cannot load the render module .*no-such-module.so" 2 --io-ranks 1 --steps 20 --render-every 10 --output "$W/pics"
    unset BASALT_RENDER_MODULE
    ;;
  io_rank_sleeps)
    # Rare output: the I/O rank's CPU time must stay a small part of the wall time (it sleeps).
    must_run 2 --io-ranks 1 --steps 600 --checkpoint-every 500 --output "$W/out"
    cat "$W/last.log"
    pct=$(sed -nE 's/.*I\/O rank CPU time .* wall \(([0-9.]+) %\).*/\1/p' "$W/last.log")
    [ -n "$pct" ] || fail "no I/O-rank CPU time in the report"
    awk -v p="$pct" 'BEGIN { exit !(p < 50) }' || fail "the I/O rank used $pct % of a core while mostly idle"
    ;;
  fields_kept_on_error)
    # Issue 16: a checkpoint that cannot be written (a folder in the way of its final name) stops the run,
    # and the fields.csv rows computed up to the stop are all there (with --io-ranks 0 they used to be
    # dropped: only the header remained).
    for q in 0 1; do
      np=$((1 + q))
      mkdir -p "$W/q$q/ckpt_000150.h5"
      must_fail "error: output failed at step [0-9]+: .*ckpt_000150.h5" $np --io-ranks $q --steps 400 \
        --checkpoint-every 50 --output "$W/q$q"
      stop=$(sed -nE 's/.*output failed at step ([0-9]+).*/\1/p' "$W/last.log" | head -1)
      rows=$(($(wc -l <"$W/q$q/fields.csv") - 1))
      [ "$rows" -eq "$stop" ] || fail "--io-ranks $q: fields.csv has $rows rows, the run stopped at step $stop"
      last_step=$(tail -1 "$W/q$q/fields.csv" | cut -d, -f1)
      [ "$last_step" = "$stop" ] || fail "--io-ranks $q: the last row is step $last_step, expected $stop"
      [ -e "$W/q$q/ckpt_000100.h5" ] || fail "--io-ranks $q: the checkpoint before the failure is gone"
      echo "--io-ranks $q: stopped at step $stop with $rows rows"
    done
    ;;
  error_reported_soon)
    # Issue 16: an I/O-rank write error reaches the compute ranks within a bounded number of steps: they
    # look for errors every 32 steps without blocking, and never hold more than frames_in_flight frames
    # whose outcome they do not know (the I/O ranks acknowledge each one). Slow storage (4 MB/s, ~0.3 s
    # per checkpoint), a checkpoint every 20 steps, and the step-100 one cannot be renamed into place:
    # the run must stop by step 100 + frames_in_flight x 20, naming the file (it used to go on for
    # hundreds of steps, or report the failure at the end).
    for fif in 1 2; do
      for np in 2 3; do
        out="$W/np$np-f$fif"
        mkdir -p "$out/ckpt_000100.h5"
        must_fail "error: output failed at step [0-9]+: .*ckpt_000100.h5" $np --io-ranks 1 --steps 3000 \
          --checkpoint-every 20 --frames-in-flight $fif --throttle-io-mbps 4 --output "$out"
        stop=$(sed -nE 's/.*output failed at step ([0-9]+).*/\1/p' "$W/last.log" | head -1)
        bound=$((100 + fif * 20))
        [ "$stop" -ge 100 ] && [ "$stop" -le $bound ] || fail "np $np, frames in flight $fif: reported at step $stop, after $bound"
        grep -q "reported at the end of the run" "$W/last.log" && fail "np $np: reported only at the end"
        rows=$(($(wc -l <"$out/fields.csv") - 1))
        [ "$rows" -eq "$stop" ] || fail "np $np: fields.csv has $rows rows, the run stopped at step $stop"
        echo "np $np (1 I/O rank), frames in flight $fif: the step-100 write error stopped the run at step $stop (bound $bound)"
      done
    done
    ;;
  stopped_by_signal)
    # Issue 16: SIGTERM or SIGINT to every rank (as a batch system's time limit or Ctrl-C delivers them):
    # the ranks stop together at the next agreement point, the rows and checkpoints computed so far are
    # written, the exit status is non-zero and the message names the signal. (A signal to mpirun itself
    # makes it send SIGTERM to the ranks and SIGKILL 1 s later, odls_base_sigkill_timeout: the same path,
    # with a deadline; docs/io-ranks.md.)
    for q in 0 1; do
      for sig in TERM INT; do
        out="$W/q$q-$sig"
        np=$((1 + q))
        "$MPIEXEC" -np $np "$BASALT_RUN" "$SCENE" --geometry "$GEOMETRY" --quiet --io-ranks $q --steps 1000000 \
          --checkpoint-every 100 --output "$out" >"$W/last.log" 2>&1 &
        mpirun_pid=$!
        for _ in $(seq 1 600); do
          [ -e "$out/ckpt_000200.h5" ] && break
          sleep 0.1
        done
        ranks=$(pgrep -P "$mpirun_pid")
        [ -n "$ranks" ] || fail "--io-ranks $q: no rank processes under mpirun"
        kill -s $sig $ranks
        wait "$mpirun_pid"
        code=$?
        cat "$W/last.log"
        [ $code -ne 0 ] || fail "--io-ranks $q, SIG$sig: exit status 0"
        grep -Eq "error: stopped by SIG$sig at step [0-9]+" "$W/last.log" || fail "--io-ranks $q, SIG$sig: no message"
        stop=$(sed -nE 's/.*stopped by SIG[A-Z]+ at step ([0-9]+).*/\1/p' "$W/last.log")
        rows=$(($(wc -l <"$out/fields.csv") - 1))
        [ "$rows" -eq "$stop" ] || fail "--io-ranks $q, SIG$sig: fields.csv has $rows rows, stopped at step $stop"
        ckpt=$(printf "%s/ckpt_%06d.h5" "$out" $((stop / 100 * 100)))
        $CHECK complete "$ckpt" || fail "--io-ranks $q, SIG$sig: $ckpt is not complete"
        echo "--io-ranks $q, SIG$sig: stopped at step $stop (exit $code), $rows rows, $ckpt complete"
      done
    done
    ;;
  blown_up_checkpoint)
    # Issue 16: two bonded particles with a time step far above the critical one (forced) and no energy
    # guard, so the oscillation grows every step. No checkpoint is written from a state with non-finite
    # values, nor from a finite blown-up one (a particle so fast that its next step trips the blow-up
    # check): the newest on disk stays a valid restart point; the run stops naming the particle, and the
    # kinetic energy column never has an empty cell (inf and nan are written).
    # Case "1.4 1.0": 31 x critical, stopped at step 1 by the blow-up check before any checkpoint.
    # Case "1.51 0.05": 1.5 x critical; the step-1 checkpoint is sound, the step-2 state has the speed
    # 10 (0.5 per step, the allowance is skin + 0.5 r = 0.35) and was saved before the frame check.
    for cfg in "1.4 1.0" "1.51 0.05"; do
      read -r x2 dt <<<"$cfg"
      printf '%s\n' "LSMGeometry 1.2" "BoundingBox 0 0 0 2 1 1" "PeriodicBoundaries 0 0 0" "Dimension 3D" \
        "BeginParticles" "Simple" "2" "0.5 0.5 0.5 0.5 1 0" "$x2 0.5 0.5 0.5 2 0" "EndParticles" \
        "BeginConnect" "1" "1 2 0" "EndConnect" >"$W/pair.geo"
      cat >"$W/blowup.toml" <<TOML
[geometry]
file = "pair.geo"
[run]
dt = $dt
steps = 400
skin = 0.1
force_dt = true
energy_check_every = 0
[[interactions]]
type = "linear_bond"
K = 1000.0
rest_length = "sum_of_radii"
[output]
directory = "out"
checkpoint_every = 1
[[output.fields]]
type = "kinetic_energy"
TOML
      for q in 0 1; do
        np=$((1 + q))
        out="$W/q$q-$dt"
        "$MPIEXEC" -np $np "$BASALT_RUN" "$W/blowup.toml" --quiet --io-ranks $q --output "$out" >"$W/last.log" 2>&1
        code=$?
        cat "$W/last.log"
        [ $code -ne 0 ] || fail "dt $dt --io-ranks $q: the blown-up run exited 0"
        grep -Eq "error: step [0-9]+: (particle id [12] went non-finite|blow-up: particle id [12] (moved|has the speed))" "$W/last.log" ||
          fail "dt $dt --io-ranks $q: no clear error"
        last=$(ls "$out"/ckpt_*.h5 2>/dev/null | sort | tail -1)
        [ "$dt" = 1.0 ] || [ -n "$last" ] || fail "dt $dt --io-ranks $q: the sound step-1 checkpoint is missing"
        /usr/bin/python3 - "$last" "$dt" <<'PY' || fail "dt $dt --io-ranks $q: $last holds a blown-up state"
import sys, h5py, numpy as np
if not sys.argv[1]:
    sys.exit(0)  # stopped before the first checkpoint: nothing was written from the blown-up state
with h5py.File(sys.argv[1], "r") as f:
    for name in ("position", "velocity"):
        if not np.isfinite(f["particles"][name][...]).all():
            sys.exit(f"{sys.argv[1]}: /particles/{name} is not finite")
    v = np.linalg.norm(f["particles"]["velocity"][...], axis=1).max()
    if v * float(sys.argv[2]) > 0.1 + 0.5 * 0.5:
        sys.exit(f"{sys.argv[1]}: a blown-up state was saved: speed {v:g}")
PY
        # Every row has its kinetic energy; the last ones are inf or nan, written as such.
        awk -F, 'NR > 1 && $3 == "" { print "empty cell: " $0; bad = 1 } END { exit bad }' "$out/fields.csv" ||
          fail "dt $dt --io-ranks $q: an empty kinetic-energy cell"
        # When the run got as far as overflowing (the blow-up check did not stop it first), that shows.
        if grep -q "went non-finite" "$W/last.log"; then
          grep -Eq ',(inf|nan)$' "$out/fields.csv" || fail "dt $dt --io-ranks $q: no inf or nan row although the energy overflowed"
        fi
        echo "dt $dt --io-ranks $q: stopped (exit $code); newest checkpoint ${last:-none} is sound"
      done
    done
    ;;
  without_vtk)
    # A build without VTK (BASALT_WITH_VTK off; registered only there): VTK frames and in-situ pictures, asked
    # for on the command line or in the scene, are refused before anything starts (no output folder), non-zero,
    # in one line naming the option, why and the way round; nothing links VTK; a run still writes its
    # checkpoints, their XDMF descriptions and the field series, and restarts from them; basalt-view's commands
    # are refused alike.
    if ldd "$BASALT_RUN" "$BASALT_VIEW" | grep -i 'libvtk'; then fail "a VTK library is linked (above)"; fi
    why='this build has none \(BASALT_WITH_VTK=OFF: [^;]+\); '
    refused() {  # refused REGEX OUTPUT_FOLDER NP ARGS...: refused, in one line of basalt-run's, nothing written
      local regex=$1 out=$2; shift 2
      must_fail "^basalt-run: error: $regex" "$@" --output "$out"
      [ "$(grep -c 'basalt-run' "$W/last.log")" -eq 1 ] || fail "the error is not one line of basalt-run's"
      [ ! -e "$out" ] || fail "the refused run created its output folder $out"
    }
    refused "--frames-every 25: VTK frames need VTK, and ${why}write checkpoints \(--checkpoint-every N\) and open ckpt_series.xmf in ParaView instead\$" \
      "$W/frames" 3 --io-ranks 1 --steps 100 --checkpoint-every 50 --frames-every 25
    refused "--render-every 50: in-situ pictures need VTK, and ${why}write checkpoints" \
      "$W/pictures" 3 --io-ranks 1 --steps 100 --render-every 50 --render "color=speed"
    refused "--render-every 5: in-situ pictures need VTK" "$W/pictures_q0" 1 --steps 10 --render-every 5
    sed 's|^\[output\]|[output]\nframes_every = 10|' "$SCENE" >"$W/frames.toml"
    SCENE=$W/frames.toml refused "output.frames_every 10: VTK frames need VTK, and $why" "$W/frames_key" 2 --steps 10
    sed 's|^\[output\]|[output]\nrender_every = 10|' "$SCENE" >"$W/render.toml"
    SCENE=$W/render.toml refused "output.render_every 10: in-situ pictures need VTK, and $why" "$W/render_key" 2 \
      --io-ranks 1 --steps 10
    # 0 means off: accepted. Then checkpoints, XDMF and fields with Q = 1 and Q = 0, and a restart.
    for q in 1 0; do
      must_run $((2 + q)) --io-ranks $q --steps 100 --checkpoint-every 25 --fields-every 1 --frames-every 0 \
        --render-every 0 --output "$W/q$q"
      $CHECK xdmf "$W/q$q" 25,50,75,100 || fail "--io-ranks $q: the XDMF descriptions are wrong"
      [ "$(wc -l <"$W/q$q/fields.csv")" -eq 101 ] || fail "--io-ranks $q: fields.csv: expected a header and 100 rows"
      [ -z "$(ls "$W/q$q" | grep -E '\.(vtp|pvtp|pvd)$|^frame_|^pictures')" ] || fail "--io-ranks $q: VTK output written"
    done
    cmp "$W/q0/fields.csv" "$W/q1/fields.csv" || fail "fields.csv differs between --io-ranks 0 and 1"
    must_run 3 --io-ranks 1 --steps 50 --checkpoint-every 25 --fields-every 1 --output "$W/q1" --restart "$W/q1/ckpt_000050.h5"
    grep -q "continuing from step 50" "$W/last.log" || fail "the restart did not continue from step 50"
    $CHECK same "$W/q0/ckpt_000100.h5" "$W/q1/ckpt_000100.h5" || fail "the restarted run's step-100 checkpoint differs"
    $CHECK xdmf "$W/q1" 25,50,75,100 || fail "after the restart from step 50: the XDMF series is wrong"
    # basalt-view: --version answers; every command is refused in one line, naming the option; nothing written.
    [ "$("$BASALT_VIEW" --version)" = "$("$BASALT_RUN" --version)" ] || fail "basalt-view --version"
    for cmd in "render $W/q1/ckpt_000100.h5 -o $W/view.png" "movie $W/q1 -o $W/view.apng" \
               "convert $W/q1/ckpt_000100.h5 -o $W/view.vtp" "plot $W/q1/fields.csv -o $W/plot.png" \
               "info $W/q1/ckpt_000100.h5"; do
      # shellcheck disable=SC2086
      if "$BASALT_VIEW" $cmd >"$W/bv.log" 2>&1; then fail "basalt-view $cmd succeeded"; fi
      cat "$W/bv.log"
      [ "$(wc -l <"$W/bv.log")" -eq 1 ] || fail "basalt-view ${cmd%% *}: not one line"
      grep -Eq "^basalt-view: error: ${cmd%% *} needs VTK, and ${why}open the run's ckpt_series.xmf in ParaView instead\$" \
        "$W/bv.log" || fail "basalt-view ${cmd%% *}: the error does not say why"
    done
    [ -z "$(ls "$W" | grep -E '^view\.|^plot\.')" ] || fail "basalt-view wrote a file"
    echo "without VTK: frames and pictures refused (command line and scene), checkpoints + XDMF + fields written, restart bit for bit"
    ;;
  *) fail "unknown case" ;;
esac
echo "PASS ($case_name)"
