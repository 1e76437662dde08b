!> Where a run's samples and events go. The solver talks to an abstract sink, so the CLI
!> streams to files (memory constant in run length) while Python collects arrays.
module impact1d_output
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_input, status_simulation, status_interrupted, fmt, fmt_width
  use impact1d_interrupt, only: interrupt_count
  use impact1d_scene, only: tutorial_bodies
  use impact1d_scene, only: scene_input, real_names, n_real, i_title, i_method, i_g, i_dt_out, i_x_left_table, &
    i_x_right_table, &
    events_all, events_impacts, events_none, events_kept, name_len, &
    i_dt, default_gravity, i_m2, springs_named, is_nbody, ground_named
  use impact1d_fields, only: n_contact_fields, contact_fields, spring_fields, sine_fields, friction_fields, &
    r_friction_name, r_name, record_input, &
    n_arrays, array_names, array_is_text
  use impact1d_files, only: output_target, make_temporary, resolve_output, lock_folders, unlock_folders, write_text, &
    lock_timed_out, lock_wait
  implicit none
  private
  public :: sink_type, memory_sink, summary_sink, file_sink, n_columns, column_names, n_event_kinds, event_names
  public :: event_impact, event_rest, event_release, event_stick, event_slip, run_stats, checkpoint
  public :: class_impact, class_rest, class_release, class_stick, class_slip, event_name, start_counts, &
    class_pair_stick, class_pair_slip, &
    count_event, event_count, impacts_on
  public :: emit_bodies, events_path, present_columns, i_pe, i_work, i_friction_loss, i_impact_loss, &
    i_damping_loss, i_drive_work, row_length, row_columns, column_word, bodies_of, row_ledger, check_bodies_out, final_row

  !> Every column a run can have; a scene's output carries those it has (present_columns):
  !> pe only with springs, damping_loss only with dampers, drive_work only with a moving ground.
  integer, parameter :: n_columns = 13, i_pe = 7, i_work = 8, i_friction_loss = 9, i_impact_loss = 10, &
    i_damping_loss = 11, i_drive_work = 12
  character(len=*), parameter :: column_names = &
    't x1 v1 x2 v2 ke pe work friction_loss impact_loss damping_loss drive_work residual'
  !> A run's full row (emit_bodies') is t, x1 v1 .. xM vM (M = max(N, 2): the tutorial's
  !> columns x2 v2 kept for one body), then these, the ledger, in this order: its length is
  !> row_length(N), the ledger's k-th at row_ledger(N) + k. N <= 2 gives the 13 above.
  integer, parameter :: n_ledger = 8
  character(len=*), parameter :: ledger_words(n_ledger) = [character(len=13) :: 'ke', 'pe', 'work', &
    'friction_loss', 'impact_loss', 'damping_loss', 'drive_work', 'residual']

  !> Events are (class, index): an impact, rest or release of row index, a stick or slip of
  !> body index; each carries the velocities of a pair of bodies (a, b; 0: none), before and
  !> after: [v_a-, v_b-, v_a+, v_b+] (docs/nbody-plan.md, "The event record"). Named
  !> '<row>', 'rest_<row>', 'release_<row>' (the row's name), 'stick<i>', 'slip<i>'; a
  !> friction contact between bodies (&friction j) sticks or slips as (class_pair_stick or
  !> class_pair_slip, n_rows + j), named 'stick_<name>', 'slip_<name>' (the sink's row_names
  !> then hold the contacts' names after the rows').
  integer, parameter :: class_impact = 1, class_rest = 2, class_release = 3, class_stick = 4, &
    class_slip = 5, class_pair_stick = 6, class_pair_slip = 7
  character(len=*), parameter :: class_prefix(7) = [character(len=8) :: '', 'rest_', 'release_', &
    'stick', 'slip', 'stick_', 'slip_']
  !> Longest event name: a prefix and a row's name.
  integer, parameter :: event_name_len = 8 + name_len
  !> The event kinds of the tutorial's scenes (its walls and slot, one or two bodies), for
  !> Python's event_kinds(); impact on left, right, slot_min, slot_max, then the rests and
  !> releases on them, stick1, stick2, slip1, slip2.
  integer, parameter :: n_event_kinds = 16
  integer, parameter :: event_impact = 0, event_rest = 4, event_release = 8, event_stick = 12, &
    event_slip = 14
  character(len=*), parameter :: event_names(n_event_kinds) = [character(len=17) :: &
    'left', 'right', 'slot_min', 'slot_max', 'rest_left', 'rest_right', 'rest_slot_min', &
    'rest_slot_max', 'release_left', 'release_right', 'release_slot_min', 'release_slot_max', &
    'stick1', 'stick2', 'slip1', 'slip2']

  !> What a run did, for the CLI's summary and Python's result.
  type :: run_stats
    integer(int64) :: steps = 0
    !> Of them, the N-body engine's closed-form steps (impact1d_nbody_glide).
    integer(int64) :: glided = 0
    !> Events counted: every one, per row (impacts, rests, releases: (3, nr)) and per body
    !> (sticks, slips: (2, N)) and per friction contact (its sticks, slips: (2, nf), the
    !> contact j's events at index nr + j); start_counts allocates them.
    integer :: n_events = 0
    integer, allocatable :: row_events(:, :), body_events(:, :), pair_events(:, :)
    !> The run's last full row (emit_bodies; row_length(N) long).
    real(wp), allocatable :: row(:)
    real(wp) :: max_residual = 0.0_wp
    !> The interrupt count when the run started (impact1d_interrupt): a run ends when it moves on.
    integer :: interrupt_epoch = 0
  end type run_stats

  !> Every sink can show progress on stderr for long runs: once a run has taken a second,
  !> a one-line '47% (t = 2.8 of 6 s, 1234 events, about 3 s left)' refreshed four times a second,
  type, abstract :: sink_type
    logical :: show_progress = .false.
    !> What the sink keeps of the event log (&run events: impact1d_scene's events_all,
    !> events_impacts, events_none); the run's counts (run_stats) have every event.
    integer :: events = events_all
    !> At most max_events of them go into the log (&run max_events); n_logged went in, n_cut
    !> would have and did not (the log then ends with a note: cut_note).
    integer :: max_events = huge(1)
    integer(int64) :: n_logged = 0, n_cut = 0
    integer(int64) :: clock_start = -1, clock_shown = 0
    logical :: progress_shown = .false.
    !> The run's row names (scene_type's row_name, set by the run): what its events are called.
    character(len=name_len), allocatable :: row_names(:)
  contains
    procedure(put_sample_interface), deferred :: put_sample
    procedure(put_event_interface), deferred :: put_event
    procedure :: progress
    procedure :: end_progress
    procedure :: keeps_event
    procedure :: logs_event
    procedure :: cut_note
  end type sink_type

  abstract interface
    !> One full row (row_length(N): emit_bodies'); the sink keeps or writes the columns it
    !> was given (row_columns). Assumed size, not shape: a descriptor per sample cost the
    !> sampling's hot path 10% (case 3, a sample every step).
    subroutine put_sample_interface(self, row)
      import :: sink_type, wp
      class(sink_type), intent(inout) :: self
      real(wp), intent(in) :: row(*)
    end subroutine put_sample_interface
    !> One event: time, class and index, the pair of bodies it reports (a, b; 0: none) and
    !> their velocities [v_a-, v_b-, v_a+, v_b+] (0 for a missing body).
    subroutine put_event_interface(self, t, class, index, a, b, v)
      import :: sink_type, wp
      class(sink_type), intent(inout) :: self
      real(wp), intent(in) :: t, v(4)
      integer, intent(in) :: class, index, a, b
    end subroutine put_event_interface
  end interface

  !> Keeps everything in arrays (the Python side copies them out).
  type, extends(sink_type) :: memory_sink
    real(wp), allocatable :: samples(:, :)      !< one column per present column, in order
    !> Or the caller's array, when it gave one (reserve's into): the rows go straight there,
    !> so a run's samples are written once, into memory that is already the result.
    real(wp), pointer :: into(:, :) => null()
    integer, allocatable :: columns(:)
    integer :: n_samples = 0
    real(wp), allocatable :: event_time(:), event_v(:, :)   !< (n), (4, n)
    integer, allocatable :: event_class(:), event_index(:)  !< (n)
    integer, allocatable :: event_ends(:, :)                !< (2, n) the reported pair
    integer :: n_events = 0
  contains
    procedure :: put_sample => memory_put_sample
    procedure :: put_event => memory_put_event
    procedure :: reserve => memory_reserve
  end type memory_sink

  !> Keeps no samples, only what a sweep's summary needs (memory O(1) per run): the last
  !> row comes in run_stats; here, since the bodies were last seen moving, the first event
  !> that left both at rest and the first sample at rest (see rest_time).
  type, extends(sink_type) :: summary_sink
    !> The run's bodies (more than two: the velocities past v2 are read too).
    integer :: n_bodies = 2
    real(wp) :: rest_event = huge(1.0_wp)    !< first event since then leaving both at rest
    real(wp) :: rest_sample = huge(1.0_wp)   !< first sample since then with both at rest
  contains
    procedure :: put_sample => summary_put_sample
    procedure :: put_event => summary_put_event
    procedure :: rest_time
  end type summary_sink

  !> Streams rows to NAME.dat and NAME.events.dat, written under temporary names and renamed
  !> only when the run succeeds and every write, flush and close did: a failed run or a full
  !> disk never leaves a truncated file under the final name, and the previous pair stays.
  type, extends(sink_type) :: file_sink
    integer :: unit = 0, event_unit = 0
    logical :: is_open = .false.
    !> The samples go to standard output as they come (-o -): no temporary, nothing to
    !> rename, and no event log unless an events file was named.
    logical :: stream = .false.
    !> A stream's text not yet written (n_pending bytes of pending): it goes out with
    !> write_text, since the Fortran runtime drops the errors of its writes to stdout (a
    !> full disk, /dev/full: the rows were lost with exit status 0).
    character(len=:), allocatable :: pending
    integer :: n_pending = 0
    !> The names given (for messages), the files they replace (the name, or the file a
    !> symbolic link there leads to: output_target) and this run's own temporary files
    !> beside those (make_temporary), which a signal guard must remove.
    character(len=:), allocatable :: path, event_path, target, event_target, part, event_part
    !> The first failed write ('file: reason'); nothing more is written after it.
    character(len=:), allocatable :: write_failure
    !> The columns this scene has, in order.
    integer, allocatable :: columns(:)
    !> Bytes written to each file, and the fixed length of a sample and an event line: the
    !> Fortran runtime may drop a full disk's error (gfortran 12 does, on write, flush and
    !> close alike), so a file is only trusted once its size on disk is what was written.
    integer(int64) :: bytes(2) = 0
    integer :: sample_bytes = 0, event_bytes = 0
    !> The scene's bodies: one or two give an event line of their velocities (v1 or v1 v2
    !> before and after), more the pair's: a b va_before vb_before va_after vb_after.
    integer :: n_bodies = 2
    !> A stream's sample line, made once (its length is the run's columns').
    character(len=:), allocatable :: line
  contains
    procedure :: put_sample => file_put_sample
    procedure :: put_event => file_put_event
    procedure :: open => file_open
    procedure :: close => file_close
    procedure, private :: put_line
    procedure, private :: finish_file
    procedure, private :: stream_put
    procedure, private :: stream_flush
  end type file_sink

  interface
    integer(c_int) function c_rename(old, new) bind(C, name='rename')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: old(*), new(*)
    end function c_rename
    integer(c_int) function c_link(old, new) bind(C, name='link')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: old(*), new(*)
    end function c_link
    integer(c_int) function c_unlink(path) bind(C, name='unlink')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function c_unlink
  end interface

  character(len=*), parameter :: row_format = '(*(es25.16e3))'
  character(len=*), parameter :: event_format = '(es25.16e3, 1x, a17, 4es25.16e3)'

contains

  !> Send one sample (t, x, v and the energy ledger; x, v, mass: every body's, N long) to a
  !> sink, keeping the run's statistics: both methods report through here, so their columns
  !> cannot drift apart. The full row (row_length(N): t, x1 v1 .. xN vN (x2 v2 zero for one
  !> body), ke, pe, work, friction_loss, impact_loss, damping_loss, drive_work, residual) in
  !> stats%row, max_residual; a row that is not finite (v = 1e300 squares to an infinite KE,
  !> and the residual becomes NaN) is an error, never a result. The sink writes the columns
  !> it was given (row_columns: the bodies of &run bodies_out, pe and damping_loss with
  !> springs), while ke and the ledger are over every body. The row is allocated once, at the
  !> run's first sample.
  !> drive_work: what moving grounds did on the bodies (given only with one: the residual
  !> then counts it).
  subroutine emit_bodies(sink, stats, t, x, v, mass, ke0, work, friction_loss, impact_loss, &
      with_springs, springs, error, drive_work)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp), intent(in) :: t, ke0, work, friction_loss, impact_loss
    real(wp), contiguous, intent(in) :: x(:), v(:), mass(:)
    logical, intent(in) :: with_springs
    real(wp), intent(in) :: springs(3)
    type(error_type), allocatable, intent(out) :: error
    real(wp), intent(in), optional :: drive_work
    real(wp) :: ke
    integer :: n, i, l
    n = size(x)
    l = row_ledger(n)
    if (.not. allocated(stats%row)) allocate(stats%row(row_length(n)))
    if (size(stats%row) /= row_length(n)) then
      deallocate(stats%row)
      allocate(stats%row(row_length(n)))
    end if
    ke = 0.5_wp * dot_product(mass, v**2)
    associate (row => stats%row)
      row(1) = t
      do i = 1, n
        row(2 * i) = x(i)
        row(2 * i + 1) = v(i)
      end do
      row(2 * n + 2:l) = 0.0_wp          ! (one body: x2, v2 of the two-body layout)
      row(l + 1) = ke
      row(l + 3) = work
      row(l + 4) = friction_loss
      row(l + 5) = impact_loss
      row(l + 7) = 0.0_wp
      if (present(drive_work)) row(l + 7) = drive_work
      if (with_springs) then
        row(l + 2) = springs(1)
        row(l + 6) = springs(3)
        row(l + 8) = ((ke + springs(1)) - (ke0 + springs(2))) - work + friction_loss + impact_loss + springs(3)
      else
        row(l + 2) = 0.0_wp
        row(l + 6) = 0.0_wp
        row(l + 8) = ke - ke0 - work + friction_loss + impact_loss
      end if
      if (present(drive_work)) row(l + 8) = row(l + 8) - drive_work
      if (.not. all(abs(row) <= huge(1.0_wp))) then
        call not_finite(t, ke, ke0, error)
        return
      end if
      stats%max_residual = max(stats%max_residual, abs(row(l + 8)))
      call sink%put_sample(row)
    end associate
  end subroutine emit_bodies

  !> The run's last full row (emit_bodies'; the ledger's k-th at row_ledger(N) + k), or
  !> n_columns zeros before any sample.
  pure function final_row(stats) result(row)
    type(run_stats), intent(in) :: stats
    real(wp), allocatable :: row(:)
    if (allocated(stats%row)) then
      row = stats%row
    else
      allocate(row(n_columns))
      row = 0.0_wp
    end if
  end function final_row

  !> A sample that is not finite: the run cannot go on.
  subroutine not_finite(t, ke, ke0, error)
    real(wp), intent(in) :: t, ke, ke0
    type(error_type), allocatable, intent(out) :: error
    call raise(error, status_simulation, 'at t = ' // trim(fmt(t)) // ': the kinetic energy or the ' // &
      'energy ledger is no longer finite (KE = ' // trim(fmt(ke)) // ', KE0 = ' // trim(fmt(ke0)) // ' J)')
  end subroutine not_finite

  !> Length of the full row of a run of n_bodies bodies: t, x and v of max(N, 2) bodies, the
  !> ledger (n_columns for one or two bodies).
  pure integer function row_length(n_bodies)
    integer, intent(in) :: n_bodies
    row_length = row_ledger(n_bodies) + n_ledger
  end function row_length

  !> Where the ledger starts in the full row: ke is at row_ledger + 1, residual at + 8.
  pure integer function row_ledger(n_bodies)
    integer, intent(in) :: n_bodies
    row_ledger = 2 * max(n_bodies, tutorial_bodies) + 1
  end function row_ledger

  !> The columns a run writes, as indices into its full row: t; x and v of the bodies named
  !> (bodies: &run bodies_out; none named: every body); ke; pe when named(1) (a spring);
  !> work, friction_loss, impact_loss; damping_loss when named(2) (a damper); drive_work
  !> when named(3) (a moving ground); residual.
  pure function row_columns(n_bodies, bodies, named) result(columns)
    integer, intent(in) :: n_bodies, bodies(:)
    logical, intent(in) :: named(3)
    integer, allocatable :: columns(:)
    integer :: l, i
    l = row_ledger(n_bodies)
    if (size(bodies) > 0) then
      columns = [1, (2 * bodies(i), 2 * bodies(i) + 1, i = 1, size(bodies))]
    else
      columns = [1, (i, i = 2, 2 * n_bodies + 1)]
    end if
    columns = [columns, l + 1]
    if (named(1)) columns = [columns, l + 2]
    columns = [columns, l + 3, l + 4, l + 5]
    if (named(2)) columns = [columns, l + 6]
    if (named(3)) columns = [columns, l + 7]
    columns = [columns, l + 8]
  end function row_columns

  !> The name of column k of a run of n_bodies bodies ('t', 'x3', 'v3', 'ke', ...).
  pure function column_word(k, n_bodies) result(word)
    integer, intent(in) :: k, n_bodies
    character(len=16) :: word     ! blank padded: callers trim
    integer :: l
    l = row_ledger(n_bodies)
    if (k == 1) then
      word = 't'
    else if (k <= l) then
      write(word, '(a, i0)') merge('x', 'v', mod(k, 2) == 0), k / 2
    else
      word = ledger_words(k - l)
    end if
  end function column_word

  !> The number of bodies of a scene as written: its arrays' (more than two), else 2 with
  !> an m2, 1 without.
  pure integer function bodies_of(input)
    type(scene_input), intent(in) :: input
    bodies_of = merge(2, 1, input%given(i_m2))
    if (is_nbody(input)) bodies_of = input%chain%n_bodies
  end function bodies_of

  !> The columns a scene's output has, as indices into its full row (row_columns): the
  !> bodies of &run bodies_out (every body when it names none), pe and damping_loss only
  !> when the scene names springs or dampers, drive_work only when it names a moving ground (a component a scene does not name is absent
  !> from its output too). One or two bodies: indices into the n_columns above.
  function present_columns(input) result(columns)
    type(scene_input), intent(in) :: input
    integer, allocatable :: columns(:)
    integer :: none(0)
    if (allocated(input%bodies_out)) then
      columns = row_columns(bodies_of(input), input%bodies_out, [springs_named(input), ground_named(input)])
    else
      columns = row_columns(bodies_of(input), none, [springs_named(input), ground_named(input)])
    end if
  end function present_columns

  !> &run bodies_out (--bodies-out), when given, names bodies of the scene in increasing order.
  subroutine check_bodies_out(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(out) :: error
    integer :: n
    if (.not. allocated(input%bodies_out)) return
    n = size(input%bodies_out)
    if (n == 0) then
      call raise(error, status_input, 'bodies_out names no body')
    else if (any(input%bodies_out < 1 .or. input%bodies_out > bodies_of(input))) then
      call raise(error, status_input, 'bodies_out names a body the scene does not have (it has ' // &
        trim(fmt(bodies_of(input))) // ')')
    else if (any(input%bodies_out(2:) <= input%bodies_out(:n - 1))) then
      call raise(error, status_input, 'bodies_out must name bodies in increasing order, each once')
    end if
  end subroutine check_bodies_out

  !> The names of the given columns of a run of n_bodies bodies, each after a space.
  subroutine names_of(columns, n_bodies, text)
    integer, intent(in) :: columns(:), n_bodies
    character(len=:), allocatable, intent(out) :: text
    integer :: k
    text = ''
    do k = 1, size(columns)
      text = text // ' ' // trim(column_word(columns(k), n_bodies))
    end do
  end subroutine names_of

  !> Whether an event of this class goes into the sink's log (the memory and file sinks ask).
  pure logical function keeps_event(self, class)
    class(sink_type), intent(in) :: self
    integer, intent(in) :: class
    keeps_event = self%events == events_all .or. (self%events == events_impacts .and. class == class_impact)
  end function keeps_event

  !> Whether this event goes into the log: a kind the log keeps, while there is room
  !> (max_events); every one past the room is counted (n_cut) for the note.
  logical function logs_event(self, class)
    class(sink_type), intent(inout) :: self
    integer, intent(in) :: class
    logs_event = self%keeps_event(class)
    if (.not. logs_event) return
    logs_event = self%n_logged < self%max_events
    if (logs_event) then
      self%n_logged = self%n_logged + 1
    else
      self%n_cut = self%n_cut + 1
    end if
  end function logs_event

  !> '' when the log holds every event it keeps, else why it stops where it does.
  subroutine cut_note(self, text)
    class(sink_type), intent(in) :: self
    character(len=:), allocatable, intent(out) :: text
    text = ''
    if (self%n_cut == 0) return
    text = 'the event log was cut at ' // trim(fmt(self%n_logged)) // ' of ' // &
      trim(fmt(self%n_logged + self%n_cut)) // ' events (max_events = ' // trim(fmt(self%max_events)) // &
      '); the run went on to its end and the counts are exact'
  end subroutine cut_note

  !> The name of event (class, index) of a run whose rows are named row_names ('left',
  !> 'rest_slot_min', 'stick1').
  pure function event_name(row_names, class, index) result(name)
    character(len=*), intent(in) :: row_names(:)
    integer, intent(in) :: class, index
    character(len=event_name_len) :: name     ! blank padded: callers trim
    character(len=12) :: body
    if (class == class_stick .or. class == class_slip) then
      write(body, '(i0)') index
      name = trim(class_prefix(class)) // body
    else
      name = trim(class_prefix(class)) // row_names(index)
    end if
  end function event_name

  !> Counts for a run of n_rows rows and n_bodies bodies, none yet.
  pure subroutine start_counts(stats, n_rows, n_bodies, n_pairs)
    type(run_stats), intent(inout) :: stats
    integer, intent(in) :: n_rows, n_bodies
    integer, intent(in), optional :: n_pairs     !< friction contacts between bodies (none: 0)
    integer :: np
    np = 0
    if (present(n_pairs)) np = n_pairs
    allocate(stats%row_events(class_impact:class_release, n_rows), stats%body_events(class_stick:class_slip, n_bodies), &
      stats%pair_events(class_pair_stick:class_pair_slip, np))
    stats%pair_events = 0
    stats%row_events = 0
    stats%body_events = 0
    stats%n_events = 0
  end subroutine start_counts

  !> One more event (class, index).
  pure subroutine count_event(stats, class, index)
    type(run_stats), intent(inout) :: stats
    integer, intent(in) :: class, index
    if (class >= class_pair_stick) then
      associate (j => index - size(stats%row_events, 2))
        stats%pair_events(class, j) = stats%pair_events(class, j) + 1
      end associate
    else if (class >= class_stick) then
      stats%body_events(class, index) = stats%body_events(class, index) + 1
    else
      stats%row_events(class, index) = stats%row_events(class, index) + 1
    end if
    stats%n_events = stats%n_events + 1
  end subroutine count_event

  !> How many events (class, index) the run had.
  pure integer function event_count(stats, class, index)
    type(run_stats), intent(in) :: stats
    integer, intent(in) :: class, index
    if (class >= class_pair_stick) then
      event_count = stats%pair_events(class, index - size(stats%row_events, 2))
    else if (class >= class_stick) then
      event_count = stats%body_events(class, index)
    else
      event_count = stats%row_events(class, index)
    end if
  end function event_count

  !> Impacts on the row called name (0 if the run has none of that name): a sweep's
  !> n_left .. n_slot_max.
  pure integer function impacts_on(stats, row_names, name)
    type(run_stats), intent(in) :: stats
    character(len=*), intent(in) :: row_names(:), name
    integer :: k
    impacts_on = 0
    k = findloc(row_names, name, dim=1)
    if (k > 0) impacts_on = stats%row_events(class_impact, k)
  end function impacts_on

  !> Every 4096 steps of a run: progress on stderr where it is shown, and an interrupt
  !> (Ctrl-C while Python waits for the run) ends the run within a fraction of a second.
  subroutine checkpoint(sink, stats, t, t_end, error)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(in) :: stats
    real(wp), intent(in) :: t, t_end
    type(error_type), allocatable, intent(inout) :: error
    call sink%progress(t, t_end, stats%n_events)
    if (interrupt_count() /= stats%interrupt_epoch) &
      call raise(error, status_interrupted, 'interrupted at t = ' // trim(fmt(t)) // ' s')
  end subroutine checkpoint

  !> Called by the stepping loop every few thousand steps: cheap unless a line is due.
  subroutine progress(self, t, t_end, n_events)
    class(sink_type), intent(inout) :: self
    real(wp), intent(in) :: t, t_end
    integer, intent(in) :: n_events     !< events logged so far
    integer(int64) :: count, rate
    character(len=8) :: percent
    character(len=16) :: now, left
    real(wp) :: elapsed
    if (.not. self%show_progress) return
    call system_clock(count, rate)
    if (self%clock_start < 0) then
      self%clock_start = count
      self%clock_shown = count
    end if
    if (count - self%clock_start < rate .or. 4 * (count - self%clock_shown) < rate) return
    self%clock_shown = count
    write(percent, '(i3, a)') int(100.0_wp * t / t_end), '%'
    write(now, '(f16.2)') t
    ! The time left at the rate so far (simulated time per second of wall time).
    elapsed = real(count - self%clock_start, wp) / real(rate, wp)
    left = '?'
    if (t > 0.0_wp) write(left, '(i0)') nint(min(elapsed * (t_end - t) / t, 1.0e15_wp), int64)
    write(error_unit, '(a)', advance='no') achar(13) // 'impact1d: ' // trim(adjustl(percent)) // &
      ' (t = ' // trim(adjustl(now)) // ' of ' // trim(fmt(t_end)) // ' s, ' // &
      trim(fmt(n_events)) // ' events, about ' // trim(adjustl(left)) // ' s left)   '
    flush(error_unit)
    self%progress_shown = .true.
  end subroutine progress

  !> Clear the progress line, if one was shown.
  subroutine end_progress(self)
    class(sink_type), intent(inout) :: self
    if (.not. self%progress_shown) return
    write(error_unit, '(a)', advance='no') achar(13) // repeat(' ', 100) // achar(13)
    flush(error_unit)
    self%progress_shown = .false.
  end subroutine end_progress

  !> Room for n_samples rows of the given columns (present_columns: only those are kept,
  !> so a scene's memory is what it has): into's first columns when given (it must have
  !> n_samples rows and size(columns) columns at least), else an array of the sink's own.
  subroutine memory_reserve(self, n_samples, columns, into)
    class(memory_sink), intent(inout) :: self
    integer, intent(in) :: n_samples, columns(:)
    real(wp), intent(inout), target, optional :: into(:, :)
    self%columns = columns
    if (allocated(self%samples)) deallocate(self%samples)
    self%into => null()
    if (present(into)) then
      self%into => into
    else
      allocate(self%samples(n_samples, size(columns)))
    end if
    self%n_samples = 0
    if (allocated(self%event_time)) deallocate(self%event_time, self%event_v, self%event_class, &
      self%event_index, self%event_ends)
    allocate(self%event_time(64), self%event_v(4, 64), self%event_class(64), self%event_index(64), &
      self%event_ends(2, 64))
    self%n_events = 0
  end subroutine memory_reserve

  subroutine summary_put_sample(self, row)
    class(summary_sink), intent(inout) :: self
    real(wp), intent(in) :: row(*)
    integer :: i
    logical :: moving
    ! (v1, v2 of a two-body row; v1 .. vN of an N-body one: t, x1 v1 .. xN vN, the ledger)
    moving = row(3) /= 0.0_wp .or. row(5) /= 0.0_wp
    do i = 3, self%n_bodies
      moving = moving .or. row(2 * i + 1) /= 0.0_wp
    end do
    if (moving) then
      self%rest_event = huge(1.0_wp)
      self%rest_sample = huge(1.0_wp)
    else if (self%rest_sample == huge(1.0_wp)) then
      self%rest_sample = row(1)
    end if
  end subroutine summary_put_sample

  subroutine summary_put_event(self, t, class, index, a, b, v)
    class(summary_sink), intent(inout) :: self
    real(wp), intent(in) :: t, v(4)
    integer, intent(in) :: class, index, a, b
    ! With one or two bodies the pair is every body; with more an event does not say whether
    ! the others move: the samples alone decide (rest_time to the sample).
    if (self%n_bodies > tutorial_bodies) return
    if (any(v(3:4) /= 0.0_wp)) then
      self%rest_event = huge(1.0_wp)
      self%rest_sample = huge(1.0_wp)
    else if (self%rest_event == huge(1.0_wp)) then
      self%rest_event = t
    end if
  end subroutine summary_put_event

  !> When every body came to rest for good: the instant from which no sample and no event
  !> shows a velocity up to t_end: the event that stopped the last body (a stick, a rest at
  !> an accumulation time, an impact leaving both still), or without one (a stop by the
  !> vissim method's threshold) the first sample at rest; NaN if a body moves at t_end.
  !> (last_row: the run's last full row, final_row's.)
  real(wp) function rest_time(self, last_row)
    class(summary_sink), intent(in) :: self
    real(wp), intent(in) :: last_row(:)
    rest_time = ieee_value(1.0_wp, ieee_quiet_nan)
    if (any(last_row(3:size(last_row) - n_ledger:2) /= 0.0_wp)) return
    rest_time = min(self%rest_event, self%rest_sample)
  end function rest_time

  subroutine memory_put_sample(self, row)
    class(memory_sink), intent(inout) :: self
    real(wp), intent(in) :: row(*)
    self%n_samples = self%n_samples + 1
    if (associated(self%into)) then
      self%into(self%n_samples, :size(self%columns)) = row(self%columns)
    else
      self%samples(self%n_samples, :) = row(self%columns)
    end if
  end subroutine memory_put_sample

  subroutine memory_put_event(self, t, class, index, a, b, v)
    class(memory_sink), intent(inout) :: self
    real(wp), intent(in) :: t, v(4)
    integer, intent(in) :: class, index, a, b
    real(wp), allocatable :: times(:), velocities(:, :)
    integer, allocatable :: classes(:), indices(:), ends(:, :)
    integer :: n
    if (.not. self%logs_event(class)) return
    n = self%n_events
    if (n == size(self%event_time)) then
      ! Geometric growth: events are rare next to steps, copies are amortised.
      allocate(times(2 * n), velocities(4, 2 * n), classes(2 * n), indices(2 * n), ends(2, 2 * n))
      times(:n) = self%event_time
      velocities(:, :n) = self%event_v
      classes(:n) = self%event_class
      indices(:n) = self%event_index
      ends(:, :n) = self%event_ends
      call move_alloc(times, self%event_time)
      call move_alloc(velocities, self%event_v)
      call move_alloc(classes, self%event_class)
      call move_alloc(indices, self%event_index)
      call move_alloc(ends, self%event_ends)
    end if
    n = n + 1
    self%n_events = n
    self%event_time(n) = t
    self%event_class(n) = class
    self%event_index(n) = index
    self%event_ends(:, n) = [a, b]
    self%event_v(:, n) = v
  end subroutine memory_put_event

  !> Open OUT (and OUT's events file: event_file when given and not '', else events_path's
  !> name) under temporary names and write the headers. OUT '-' is standard output (stream):
  !> the samples are written there as they come, and the event log only to an event_file.
  subroutine file_open(self, path, input, error, event_file)
    class(file_sink), intent(inout) :: self
    character(len=*), intent(in) :: path
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(out) :: error
    character(len=*), intent(in), optional :: event_file
    integer :: ios, k
    character(len=512) :: message
    character(len=:), allocatable :: header, samples_file, events_file
    logical :: named_events

    named_events = .false.
    if (present(event_file)) named_events = len(event_file) > 0
    self%path = path
    self%stream = path == '-'
    self%event_path = trim(events_path(path))
    if (named_events) self%event_path = event_file
    if (path(len(path):) == '/') then
      call raise(error, status_input, 'cannot write output ' // path // ': it is a folder (give a file name)')
      return
    end if
    self%target = ''
    self%event_target = ''
    if (.not. self%stream) call output_target(self%path, self%target, error)
    if (allocated(error)) return
    if (named_events .or. .not. self%stream) call output_target(self%event_path, self%event_target, error)
    if (allocated(error)) return
    ! Two links leading to one file would make the pair one file, and so would an events
    ! file named as the output (--events-file), existing or not.
    samples_file = ''
    events_file = ''
    if (len(self%target) > 0) call resolve_output(self%target, samples_file)     ! (none for a stream)
    if (len(self%event_target) > 0) call resolve_output(self%event_target, events_file)
    if (len(samples_file) > 0 .and. samples_file == events_file) then
      call raise(error, status_input, 'cannot write output ' // path // ': it and its events file ' // &
        self%event_path // ' are the same file ' // samples_file)
      return
    end if
    self%unit = output_unit
    self%part = ''
    if (self%stream) allocate(character(len=65536) :: self%pending)
    self%n_pending = 0
    ios = 0
    if (.not. self%stream) call make_temporary(self%target, self%unit, self%part, ios, message)
    if (ios /= 0) then
      call raise(error, status_input, 'cannot write output ' // path // ': ' // trim(reason(message)))
      return
    end if
    self%events = events_kept(input)
    if (self%stream .and. .not. named_events) self%events = events_none
    self%event_part = ''
    ios = 0
    if (self%events /= events_none) &
      call make_temporary(self%event_target, self%event_unit, self%event_part, ios, message)
    if (ios /= 0) then
      if (.not. self%stream) close(self%unit, status='delete')
      call raise(error, status_input, 'cannot write output ' // self%event_path // ': ' // trim(reason(message)))
      return
    end if
    self%is_open = .true.
    self%bytes = 0
    self%columns = present_columns(input)
    self%sample_bytes = line_bytes(row_format, 0.0_wp, size(self%columns))
    allocate(character(len=25 * size(self%columns)) :: self%line)
    self%n_bodies = bodies_of(input)
    self%event_bytes = line_bytes(event_format, 0.0_wp, 2 * min(self%n_bodies, 2), event_names(1))
    call self%put_line(self%unit, '# impact1d output')
    call self%put_line(self%unit, '# title = ' // trim(input%text(i_title)%s))
    if (allocated(input%source)) call self%put_line(self%unit, '# scene = ' // input%source)
    if (len_trim(input%text(i_method)%s) > 0) then
      call self%put_line(self%unit, '# method = ' // trim(input%text(i_method)%s))
    else
      call self%put_line(self%unit, '# method = event')
    end if
    ! (the walls' tables, as the records' ground_table: the path as the run read it)
    if (len_trim(input%text(i_x_left_table)%s) > 0) &
      call self%put_line(self%unit, '# x_left_table = ' // trim(input%text(i_x_left_table)%s))
    if (len_trim(input%text(i_x_right_table)%s) > 0) &
      call self%put_line(self%unit, '# x_right_table = ' // trim(input%text(i_x_right_table)%s))
    do k = 1, n_real
      if (input%given(k)) then
        call self%put_line(self%unit, '# ' // trim(real_names(k)) // ' = ' // trim(fmt(input%value(k))))
      else if (k == i_g) then
        call self%put_line(self%unit, '# g = ' // trim(fmt(default_gravity)))
      else if (k == i_dt_out) then
        call self%put_line(self%unit, '# dt_out = ' // trim(fmt(input%value(i_dt))))
      end if
    end do
    ! (one or two bodies: their arrays are folded into the names above, but for the friction
    ! laws', which have no such names: impact1d_chain's fold)
    call put_arrays(self, input)
    call put_records(self, input)
    if (self%n_bodies > tutorial_bodies) call self%put_line(self%unit, '# bodies = ' // trim(fmt(self%n_bodies)))
    call names_of(self%columns, self%n_bodies, header)
    call self%put_line(self%unit, '#' // header)
    if (self%events == events_none) return
    call self%put_line(self%event_unit, '# impact1d events')
    if (self%n_bodies > tutorial_bodies) then
      call self%put_line(self%event_unit, '# t kind a b va_before vb_before va_after vb_after')
    else if (self%n_bodies == 2) then
      call self%put_line(self%event_unit, '# t kind v1_before v2_before v1_after v2_after')
    else
      call self%put_line(self%event_unit, '# t kind v1_before v1_after')
    end if
  end subroutine file_open

  subroutine file_put_sample(self, row)
    class(file_sink), intent(inout) :: self
    real(wp), intent(in) :: row(*)
    integer :: ios
    character(len=512) :: message
    if (allocated(self%write_failure)) return
    if (self%stream) then
      write(self%line, row_format) row(self%columns)
      call self%stream_put(trim(self%line))
      return
    end if
    write(self%unit, row_format, iostat=ios, iomsg=message) row(self%columns)
    if (ios /= 0) self%write_failure = self%path // ': ' // trim(reason(message))
    self%bytes(1) = self%bytes(1) + self%sample_bytes
  end subroutine file_put_sample

  subroutine file_put_event(self, t, class, index, a, b, v)
    class(file_sink), intent(inout) :: self
    real(wp), intent(in) :: t, v(4)
    integer, intent(in) :: class, index, a, b
    integer :: ios
    character(len=512) :: message
    if (allocated(self%write_failure)) return
    if (.not. self%logs_event(class)) return
    ! One or two bodies: the pair is (1, 2), or (1, 0) with one body, whose line has v1 only;
    ! more: the pair's ends, named (a line of its own length, counted as written).
    if (self%n_bodies > tutorial_bodies) then
      call put_pair_event(self, t, event_name(self%row_names, class, index), a, b, v)
      return
    else if (self%n_bodies == 2) then
      write(self%event_unit, event_format, iostat=ios, iomsg=message) t, &
        event_name(self%row_names, class, index), v
    else
      write(self%event_unit, event_format, iostat=ios, iomsg=message) t, &
        event_name(self%row_names, class, index), v(1), v(3)
    end if
    if (ios /= 0) self%write_failure = self%event_path // ': ' // trim(reason(message))
    self%bytes(2) = self%bytes(2) + self%event_bytes
  end subroutine file_put_event

  !> An N-body event line: t kind a b va_before vb_before va_after vb_after (the kind as
  !> long as it is: the line's length is counted as written).
  subroutine put_pair_event(self, t, kind, a, b, v)
    class(file_sink), intent(inout) :: self
    real(wp), intent(in) :: t, v(4)
    character(len=*), intent(in) :: kind
    integer, intent(in) :: a, b
    character(len=25 * 5 + 2 * 12 + event_name_len + 1) :: line
    write(line, '(es25.16e3, 1x, a, 2(1x, i0), 4es25.16e3)') t, trim(kind), a, b, v
    call self%put_line(self%event_unit, trim(line))
  end subroutine put_pair_event

  !> The number arrays of a scene in the header (of one or two bodies only the friction
  !> laws': belt_v, v_s, c_v, belt_amp, belt_period, belt_phase), a line each with its values ('# m = 1.0 2.0 5.0'), so that a
  !> reader rebuilds the scene (read_output);
  !> like the tutorial's table names, the force tables' names are not written.
  subroutine put_arrays(self, input)
    class(file_sink), intent(inout) :: self
    type(scene_input), intent(in) :: input
    character(len=:), allocatable :: line
    character(len=fmt_width) :: text
    integer :: a, i, used, width
    ! The line is filled in place (appending value by value copied it whole each time), and a
    ! value equal to the one before (to the bit: m = 10000*1.0) is not formatted again.
    do a = 1, n_arrays
      associate (array => input%chain%array(a))
        if (array%n == 0 .or. array_is_text(a)) cycle
        deallocate(line, stat=i)
        allocate(character(len=len_trim(array_names(a)) + 4 + array%n * (fmt_width + 1)) :: line)
        used = len_trim(array_names(a)) + 4
        line(:used) = '# ' // trim(array_names(a)) // ' ='
        do i = 1, array%n
          if (i == 1) then
            text = fmt(array%v(i))
          else if (transfer(array%v(i), 0_int64) /= transfer(array%v(i - 1), 0_int64)) then
            text = fmt(array%v(i))
          end if
          width = len_trim(text)
          line(used + 1:used + 1 + width) = ' ' // text(:width)
          used = used + 1 + width
        end do
        call self%put_line(self%unit, line(:used))
      end associate
    end do
  end subroutine put_arrays

  !> The scene's &contact, &spring, &sine and &friction records in the header, a line per
  !> given field in the form of the others ('# contact.2.d_min = 0.5', '# spring.1.k = 40.0',
  !> '# sine.1.amp = 2.0', '# friction.1.name = pad'), so that a reader rebuilds the scene
  !> (impact1d.read_output: Scene.contacts, springs, sines, frictions).
  subroutine put_records(self, input)
    class(file_sink), intent(inout) :: self
    type(scene_input), intent(in) :: input
    if (allocated(input%chain%contacts)) call put_numeric_records(self, 'contact', contact_fields, &
      input%chain%contacts, r_name)
    if (allocated(input%chain%springs)) call put_numeric_records(self, 'spring', spring_fields, input%chain%springs, 0)
    if (allocated(input%chain%sines)) call put_numeric_records(self, 'sine', sine_fields, input%chain%sines, 0)
    if (allocated(input%chain%frictions)) call put_numeric_records(self, 'friction', friction_fields, &
      input%chain%frictions, r_friction_name)
  end subroutine put_records

  !> Records, a line per given field ('# group.r.field = value'); field name_field (0: none)
  !> is the record's name, written when not blank; ground_table its table's path (as read:
  !> relative to the folder the run started in, or absolute).
  subroutine put_numeric_records(self, group, fields, records, name_field)
    class(file_sink), intent(inout) :: self
    character(len=*), intent(in) :: group, fields(:)
    type(record_input), intent(in) :: records(:)
    integer, intent(in) :: name_field
    integer :: r, f
    character(len=32) :: key
    do r = 1, size(records)
      do f = 1, size(fields)
        write(key, '(a, ".", i0, ".", a)') group, r, trim(fields(f))
        if (fields(f) == 'ground_table') then
          if (allocated(records(r)%table)) call self%put_line(self%unit, '# ' // trim(key) // ' = ' // records(r)%table)
        else if (f /= name_field .and. records(r)%given(f)) then
          call self%put_line(self%unit, '# ' // trim(key) // ' = ' // trim(fmt(records(r)%value(f))))
        end if
      end do
      if (name_field == 0 .or. .not. allocated(records(r)%name)) cycle
      write(key, '(a, ".", i0, ".name")') group, r
      if (len_trim(records(r)%name) > 0) call self%put_line(self%unit, '# ' // trim(key) // ' = ' // records(r)%name)
    end do
  end subroutine put_numeric_records

  !> A header line, checked like every row.
  subroutine put_line(self, unit, text)
    class(file_sink), intent(inout) :: self
    integer, intent(in) :: unit
    character(len=*), intent(in) :: text
    integer :: ios
    character(len=512) :: message
    if (allocated(self%write_failure)) return
    if (self%stream .and. unit == self%unit) then
      call self%stream_put(text)
      return
    end if
    write(unit, '(a)', iostat=ios, iomsg=message) text
    if (ios /= 0 .and. unit == self%unit) self%write_failure = self%path // ': ' // trim(reason(message))
    if (ios /= 0 .and. unit /= self%unit) self%write_failure = self%event_path // ': ' // trim(reason(message))
    if (unit == self%unit) self%bytes(1) = self%bytes(1) + len(text) + 1
    if (unit /= self%unit) self%bytes(2) = self%bytes(2) + len(text) + 1
  end subroutine put_line

  !> A line for a stream (a sample or header line, without its newline).
  subroutine stream_put(self, text)
    class(file_sink), intent(inout) :: self
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: why
    if (self%n_pending + len(text) + 1 > len(self%pending)) call self%stream_flush()
    if (len(text) + 1 > len(self%pending)) then      ! (a header line longer than the buffer)
      call write_text(1, text // new_line('a'), why)
      if (len(why) > 0 .and. .not. allocated(self%write_failure)) self%write_failure = 'standard output: ' // why
      return
    end if
    self%pending(self%n_pending + 1:self%n_pending + len(text) + 1) = text // new_line('a')
    self%n_pending = self%n_pending + len(text) + 1
  end subroutine stream_put

  !> Write a stream's pending text, noting the first failure.
  subroutine stream_flush(self)
    class(file_sink), intent(inout) :: self
    character(len=:), allocatable :: why
    if (self%n_pending == 0 .or. allocated(self%write_failure)) return
    call write_text(1, self%pending(:self%n_pending), why)
    self%n_pending = 0
    if (len(why) > 0) self%write_failure = 'standard output: ' // why
  end subroutine stream_flush

  !> Close the files. Only if the run succeeded and every write, flush and close did, the new
  !> pair replaces the previous one (replace_pair); otherwise the temporary files are removed
  !> and a failed write is reported (status 2: the run could not deliver its output).
  subroutine file_close(self, keep, error)
    class(file_sink), intent(inout) :: self
    logical, intent(in) :: keep
    type(error_type), allocatable, intent(out) :: error
    integer :: ios
    character(len=:), allocatable :: note
    call self%end_progress()
    if (.not. self%is_open) return
    self%is_open = .false.
    if (keep) then
      call self%finish_file(self%unit, self%path, self%part)
      call self%cut_note(note)
      if (len(note) > 0 .and. self%events /= events_none) call self%put_line(self%event_unit, '# ' // note)
      if (self%events /= events_none) call self%finish_file(self%event_unit, self%event_path, self%event_part)
    else
      ! Standard output stays open (the rows before the failure go out).
      if (self%stream) call self%stream_flush()
      if (.not. self%stream) close(self%unit, iostat=ios)
      if (self%events /= events_none) close(self%event_unit, iostat=ios)
    end if
    if (keep .and. .not. allocated(self%write_failure)) then
      ! A stream without an events file has nothing to put in place.
      if (self%stream .and. len(self%event_target) == 0) return
      call replace_pair(self, error)
      if (.not. allocated(error)) return
    end if
    call remove_file(self%part)
    if (len(self%event_part) > 0) call remove_file(self%event_part)
    if (keep .and. allocated(self%write_failure)) &
      call raise(error, status_simulation, 'cannot write output ' // self%write_failure)
  end subroutine file_close

  !> Flush and close one file, recording the first failure (a full disk often shows only here,
  !> when the last buffer goes out).
  subroutine finish_file(self, unit, path, part)
    class(file_sink), intent(inout) :: self
    integer, intent(in) :: unit
    character(len=*), intent(in) :: path, part
    integer :: ios
    integer(int64) :: on_disk, written
    character(len=512) :: message
    if (self%stream .and. unit == self%unit) then
      call self%stream_flush()
      return
    end if
    if (.not. allocated(self%write_failure)) then
      flush(unit, iostat=ios, iomsg=message)
      if (ios /= 0) self%write_failure = path // ': ' // trim(reason(message))
    end if
    if (allocated(self%write_failure)) then
      close(unit, iostat=ios)
      return
    end if
    close(unit, iostat=ios, iomsg=message)
    if (ios /= 0) self%write_failure = path // ': ' // trim(reason(message))
    if (allocated(self%write_failure)) return
    written = self%bytes(merge(1, 2, unit == self%unit))
    inquire(file=part, size=on_disk)
    if (on_disk /= written) self%write_failure = path // ': only ' // trim(fmt(on_disk)) // ' of ' // &
      trim(fmt(written)) // ' bytes reached the disk (is it full?)'
  end subroutine finish_file

  !> Length in bytes (with its newline) of a line written with a fixed-width format.
  integer function line_bytes(format, value, n_values, name)
    character(len=*), intent(in) :: format
    real(wp), intent(in) :: value
    integer, intent(in) :: n_values
    character(len=*), intent(in), optional :: name
    ! (as long as the line may be: es25.16e3 is 25 characters a value, and 1000 bodies
    ! write 2008 values; a fixed buffer of 1024 ended the run with 'End of record')
    character(len=:), allocatable :: line
    real(wp) :: values(n_values)
    integer :: extra
    extra = 0
    if (present(name)) extra = len(name)
    allocate(character(len=32 * (n_values + 1) + extra) :: line)
    values = value
    if (present(name)) then
      write(line, format) value, name, values
    else
      write(line, format) values
    end if
    line_bytes = len_trim(line) + 1
  end function line_bytes

  !> Put the finished temporary files under their final names as a pair: either both new
  !> files end up there, or (a rename failed) both previous ones stay. The previous files
  !> are kept as hard links (or, where links are not supported, moved aside) under this
  !> run's own names (its temporary's with .previous for .part) until both renames have
  !> succeeded. Runs putting outputs in the same folders do it one after the other
  !> (lock_folders), so the pair in place is always one run's.
  subroutine replace_pair(self, error)
    class(file_sink), intent(in) :: self
    type(error_type), allocatable, intent(out) :: error
    logical :: kept(2), placed(2)
    character(len=len(self%target) + len(self%event_target)) :: final(2)
    character(len=len(self%part) + len(self%event_part) + 4) :: part(2), aside(2)
    integer :: k, locks(2)
    integer(c_int) :: status, undone

    final(1) = self%target
    final(2) = self%event_target
    part(1) = self%part
    part(2) = self%event_part
    aside(1) = part(1)(:len_trim(part(1)) - len('.part')) // '.previous'
    aside(2) = part(2)(:len_trim(part(2)) - len('.part')) // '.previous'
    if (len_trim(part(2)) == 0) aside(2) = part(1)(:len_trim(part(1)) - len('.part')) // '.events.previous'
    if (len_trim(final(1)) == 0) final(1) = final(2)      ! a stream: the events file alone
    call lock_folders(trim(final(1)), trim(final(2)), locks)
    if (any(locks == lock_timed_out)) then
      call raise(error, status_simulation, 'cannot write output ' // self%path // &
        ': another process has held the lock on its folder for ' // trim(fmt(real(lock_wait(), wp))) // &
        ' s (stopped or hung while putting its own output in place? IMPACT1D_LOCK_WAIT sets the wait)')
      return
    end if
    kept = .false.
    placed = .false.
    do k = 1, 2
      if (len_trim(part(k)) == 0 .and. k == 1) cycle       ! (a stream's samples: no file)
      if (.not. exists(trim(final(k)))) cycle
      kept(k) = c_link(trim(final(k)) // c_null_char, trim(aside(k)) // c_null_char) == 0
      if (.not. kept(k)) kept(k) = c_rename(trim(final(k)) // c_null_char, trim(aside(k)) // c_null_char) == 0
    end do
    status = 0
    do k = 2, 1, -1
      ! Without an event log (events = 'none') the previous events file is set aside like
      ! the samples and removed with them: an old log must not pass for this run's.
      if (len_trim(part(k)) == 0) cycle
      status = c_rename(trim(part(k)) // c_null_char, trim(final(k)) // c_null_char)
      if (status /= 0) exit
      placed(k) = .true.
    end do
    do k = 1, 2
      if (status /= 0) then
        ! Undo: the previous file back under its name (or no file, if there was none).
        if (placed(k) .and. .not. kept(k)) call remove_file(trim(final(k)))
        if (kept(k)) undone = c_rename(trim(aside(k)) // c_null_char, trim(final(k)) // c_null_char)
      else if (kept(k)) then
        ! (no new file took the name: the previous one goes, see above)
        if (len_trim(part(k)) == 0) call remove_file(trim(final(k)))
        call remove_file(trim(aside(k)))
      end if
    end do
    call unlock_folders(locks)
    if (status /= 0) call raise(error, status_simulation, 'cannot put the finished output in place as ' // self%path)
  end subroutine replace_pair

  logical function exists(path)
    character(len=*), intent(in) :: path
    inquire(file=path, exist=exists)
  end function exists

  !> Remove a file if it is there (a missing one is fine).
  subroutine remove_file(path)
    character(len=*), intent(in) :: path
    integer(c_int) :: status
    status = c_unlink(path // c_null_char)
  end subroutine remove_file

  !> The events file of an output: its extension, whatever it is, becomes .events.dat
  !> (res.dat, res.txt and res all give res.events.dat).
  pure function events_path(path) result(events)
    character(len=*), intent(in) :: path
    character(len=len(path) + 11) :: events     ! blank padded: callers trim
    integer :: slash, dot, name_start
    slash = index(path, '/', back=.true.)
    dot = index(path(slash + 1:), '.', back=.true.)
    ! Leading dots name a hidden file, not an extension (as Python's os.path.splitext).
    name_start = verify(path(slash + 1:), '.')
    if (name_start > 0 .and. dot > name_start) then
      events = path(:slash + dot - 1) // '.events.dat'
    else
      events = path // '.events.dat'
    end if
  end function events_path

  !> The system's reason from an open's message, without the file name it quotes: that is
  !> the temporary name, which means nothing to the user.
  pure function reason(message) result(text)
    character(len=*), intent(in) :: message
    character(len=len(message)) :: text     ! blank padded: callers trim
    integer :: quote_end
    quote_end = index(message, ''': ', back=.true.)
    text = message
    if (quote_end > 0) text = message(quote_end + 3:)
  end function reason

end module impact1d_output
