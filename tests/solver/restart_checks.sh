# Sourced by the restart tests (restart_*.sh): the steps every "2N straight, N then N restarted" check repeats.
# seed_restart A B N: folder B gets run A's step-N checkpoint and A's fields.csv rows up to step N (saved every
# 10 steps), which the restart from B continues.
seed_restart() {
  mkdir -p "$2"
  cp "$1/ckpt_$(printf %06d "$3").h5" "$2/"
  head -n $(($3 / 10 + 1)) "$1/fields.csv" > "$2/fields.csv"
}
# same_fields A B [NAME]: B's fields.csv must equal A's byte for byte; NAME (default "the restarted run")
# names B's run in the PASS and FAIL lines. Exits 1 on a difference, after its first lines.
same_fields() {
  what=${3:-the restarted run}
  if cmp -s "$1/fields.csv" "$2/fields.csv"; then
    echo "PASS: $what's $(wc -l < "$2/fields.csv") rows equal the uninterrupted run's"
  else
    diff "$1/fields.csv" "$2/fields.csv" | head -5
    echo "FAIL: $what differs"
    exit 1
  fi
}
