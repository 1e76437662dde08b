!> impact1d command line: a thin main over the library. Reads a scene, applies the options,
!> streams the run to OUT.dat and OUT.events.dat (or the samples to standard output: -o -),
!> prints a summary. Any error: one line on
!> stderr and a non-zero exit status (1 bad input, 2 the run could not go on).
program impact1d_cli
  use, intrinsic :: iso_fortran_env, only: error_unit
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, status_input, status_simulation, fmt
  use impact1d_scene, only: scene_input, scene_type, set_text, i_t_end, i_dt, i_dt_out, i_max_events, i_method, &
    i_events, i_title, events_none, events_impacts, i_f1_table, i_f2_table, name_len
  use impact1d_io, only: read_scene_file, prepare_scene, lower, read_body_list
  use impact1d_output, only: file_sink, events_path, class_impact, class_stick, class_slip, event_name, event_count, &
    class_pair_stick, class_pair_slip, &
    check_bodies_out, row_ledger, final_row
  use impact1d_files, only: make_folders, resolve, write_text
  use impact1d_solver, only: run, run_stats
  use impact1d_version, only: version
  implicit none

  interface
    subroutine c_exit(status) bind(C, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
    !> app/impact1d_signals.c: an interrupted run removes its temporary files.
    subroutine guard_temporaries(first, second) bind(C, name='impact1d_guard_temporaries')
      import :: c_char
      character(kind=c_char), intent(in) :: first(*), second(*)
    end subroutine guard_temporaries
    subroutine hold_signals() bind(C, name='impact1d_hold_signals')
    end subroutine hold_signals
    subroutine release_signals() bind(C, name='impact1d_release_signals')
    end subroutine release_signals
    subroutine allow_signals() bind(C, name='impact1d_allow_signals')
    end subroutine allow_signals
    integer(c_int) function c_isatty(fd) bind(C, name='isatty')
      import :: c_int
      integer(c_int), value :: fd
    end function c_isatty
  end interface

  character(len=*), parameter :: usage = &
    'usage: impact1d SCENE [--t-end T] [--dt DT] [--dt-out DT_OUT] [--method event|vissim] [-o OUT.dat]' // &
    ' [--events all|impacts|none] [--events-file FILE] [--max-events N] [--bodies-out I,J,..] [--quiet]'
  character(len=*), parameter :: nl = new_line('a')
  character(len=*), parameter :: help = usage // nl // nl // &
    'Runs SCENE (a namelist scene, or a VisSim-style .dat parameter file) and writes its samples' // nl // &
    'to OUT.dat (default output/SCENE_NAME.dat; missing folders are created), its event log to' // nl // &
    'OUT.events.dat (OUT without its extension, plus .events.dat) and a summary to stdout.' // nl // nl // &
    'Options override the scene''s &run values; write them --dt 1e-3 or --dt=1e-3:' // nl // &
    '  --t-end T        end time (s)       .dat scenes have no &run: give --t-end and --dt' // nl // &
    '  --dt DT          integrator step (s)' // nl // &
    '  --dt-out DT_OUT  time between samples (s); default dt; finer or coarser than dt' // nl // &
    '  --method NAME    event   event-driven: every impact, stop and break-away located (default)' // nl // &
    '                   vissim  the VisSim tutorial''s fixed-step scheme, O(dt) (any letter case)' // nl // &
    '  -o OUT.dat       where the samples go (never one of the run''s own input files; a link' // nl // &
    '                   to a regular file is written through, a FIFO or a device refused);' // nl // &
    '                   -o - (or /dev/stdout): to standard output as they come, the summary' // nl // &
    '                   to stderr, and no event log unless --events-file names one' // nl // &
    '  --events WHAT    what the event log keeps: all (default), impacts, or none (no events' // nl // &
    '                   file; an earlier one beside OUT.dat is removed); counts stay exact' // nl // &
    '  --events-file F  the event log goes to F (default OUT.events.dat)' // nl // &
    '  --max-events N   the log keeps the first N events (default 10^7); then it ends with a' // nl // &
    '                   note, the run goes on and the summary''s counts stay exact' // nl // &
    '  --bodies-out L   the samples have x and v of the bodies listed (1,10,20: increasing),' // nl // &
    '                   not of every body; ke and the ledger stay over every body' // nl // &
    '  --quiet          no progress line (a run of over a second on a terminal shows one on' // nl // &
    '                   stderr: the simulated time, events so far and the time left; never' // nl // &
    '                   in a pipe or a file)' // nl // &
    '  -h, --help       this text' // nl // &
    '  --version        the version' // nl // nl // &
    'Exit status: 0 done; 1 bad input (scene, tables, options, output path), nothing written;' // nl // &
    '2 the run could not go on (the reason and the time on stderr), nothing written, or the' // nl // &
    'summary could not be written to stdout. A signal removes the temporary files and ends' // nl // &
    'the run as it would any program (the previous output stays). Only regular files are read.' // nl // &
    'Formats and method: docs/formats.md, docs/method.md in the impact1d sources.'
  type(scene_input) :: input
  type(scene_type) :: scene
  type(file_sink) :: sink
  type(run_stats) :: stats
  type(error_type), allocatable :: error, close_error
  character(len=:), allocatable :: scene_path, out_path, option, value, events_file
  integer :: i, n_args, k, c, equals
  integer, allocatable :: bodies_out(:)
  real(wp) :: overrides(4)
  logical :: overridden(4), has_value, out_given, quiet, stream, ok
  character(len=64) :: method, events
  !> The fields --t-end, --dt, --dt-out, --max-events override, in that order.
  integer, parameter :: overridable(4) = [i_t_end, i_dt, i_dt_out, i_max_events]

  overridden = .false.
  overrides = 0.0_wp
  method = ''
  events = ''
  scene_path = ''
  out_path = ''
  events_file = ''
  stream = .false.
  out_given = .false.
  quiet = .false.
  n_args = command_argument_count()
  i = 1
  do while (i <= n_args)
    option = argument_text(i)
    i = i + 1
    ! GNU style: --dt=1e-3 is --dt 1e-3.
    has_value = .false.
    equals = index(option, '=')
    if (equals > 3 .and. index(option, '--') == 1) then
      value = option(equals + 1:)
      option = option(:equals - 1)
      has_value = .true.
    end if
    select case (option)
    case ('-h', '--help')
      call say(help // nl, 'the help')
      stop
    case ('--version')
      call say('impact1d ' // version // nl, 'the version')
      stop
    case ('--quiet')
      if (has_value) call fail(status_input, '--quiet takes no value; ' // usage)
      quiet = .true.
    case ('--t-end', '--dt', '--dt-out', '--max-events', '--method', '--events', '--events-file', '-o', &
        '--bodies-out')
      if (.not. has_value) then
        if (i > n_args) call fail(status_input, option // ' needs a value')
        value = argument_text(i)
        i = i + 1
      end if
      select case (option)
      case ('--method')
        if (len_trim(value) == 0) call fail(status_input, '--method needs a name: event or vissim')
        method = lower(trim(adjustl(value)))
      case ('--events')
        if (len_trim(value) == 0) call fail(status_input, '--events needs a word: all, impacts or none')
        events = lower(trim(adjustl(value)))
      case ('-o')
        ! An empty name is a mistake (an unset shell variable), not a request for the default.
        if (len_trim(value) == 0) call fail(status_input, '-o needs a file name, got an empty one')
        out_path = value
        out_given = .true.
      case ('--events-file')
        if (len_trim(value) == 0) call fail(status_input, '--events-file needs a file name, got an empty one')
        if (standard_output(value)) call fail(status_input, '--events-file ' // value // &
          ': the event log cannot go to standard output (give a file name)')
        events_file = value
      case ('--t-end')
        call override(1)
      case ('--dt')
        call override(2)
      case ('--dt-out')
        call override(3)
      case ('--max-events')
        call override(4)
      case ('--bodies-out')
        call read_body_list(value, bodies_out, ok)
        if (.not. ok) call fail(status_input, '--bodies-out needs body numbers separated by commas (1,10,20), ' // &
          'got ''' // value // '''')
      end select
    case default
      if (has_value) call fail(status_input, 'unknown option ' // option // '; ' // usage)
      if (len(option) > 1) then
        if (option(1:1) == '-') call fail(status_input, 'unknown option ' // option // '; ' // usage)
      end if
      if (len(option) == 0) call fail(status_input, 'an empty argument is not a scene; ' // usage)
      if (len(scene_path) > 0) call fail(status_input, 'one scene at a time; ' // usage)
      scene_path = option
    end select
  end do
  if (len(scene_path) == 0) call fail(status_input, usage)

  call read_scene_file(scene_path, input, error)
  if (allocated(error)) call fail(error%status, error%message)
  input%value(overridable) = merge(overrides, input%value(overridable), overridden)
  input%given(overridable) = input%given(overridable) .or. overridden
  if (len_trim(method) > 0) call set_text(input, i_method, trim(method))
  if (len_trim(events) > 0) call set_text(input, i_events, trim(events))
  if (allocated(bodies_out)) input%bodies_out = bodies_out
  call prepare_scene(input, scene, error)
  if (.not. allocated(error)) call check_bodies_out(input, error)
  if (allocated(error)) call fail(error%status, scene_path // ': ' // error%message)

  if (.not. out_given) out_path = 'output/' // stem(scene_path) // '.dat'
  ! Standard output by any of its names is a stream (through /dev/stdout's link the output
  ! used to replace the file stdout was redirected to, and the summary was lost with it).
  stream = standard_output(out_path)
  if (len(events_file) > 0 .and. scene%events == events_none) call fail(status_input, '--events-file ' // &
    events_file // ': the scene keeps no event log (events = ''none'')')
  if (.not. stream) then
    call refuse_to_overwrite_inputs(out_path)
    call make_folders(out_path, error)
    if (allocated(error)) call fail(error%status, error%message)
  end if
  if (len(events_file) == 0 .and. .not. stream) call refuse_to_overwrite_inputs(trim(events_path(out_path)))
  if (len(events_file) > 0) then
    call refuse_to_overwrite_inputs(events_file)
    call make_folders(events_file, error)
    if (allocated(error)) call fail(error%status, error%message)
  end if
  ! Held from creating the temporary files until they are registered: a signal in between
  ! would otherwise leave them behind.
  sink%max_events = scene%max_events
  call hold_signals()
  if (stream) then
    call sink%open('-', input, error, events_file)
  else
    call sink%open(out_path, input, error, events_file)
  end if
  if (allocated(error)) then
    call release_signals()
    call fail(error%status, error%message)
  end if
  call guard_temporaries(sink%part // c_null_char, sink%event_part // c_null_char)
  call allow_signals()
  ! Progress only where a person watches: stderr a terminal (file descriptor 2).
  sink%show_progress = c_isatty(2_c_int) == 1 .and. .not. quiet
  call run(scene, sink, stats, error)
  call hold_signals()
  call sink%close(.not. allocated(error), close_error)
  call release_signals()
  if (allocated(error)) call fail(error%status, scene_path // ': ' // error%message)
  if (allocated(close_error)) call fail(close_error%status, close_error%message)
  call summary()

contains

  !> The summary's line of the final state: t, then x and v of the bodies written (&run
  !> bodies_out, or every body; the first ten of them).
  subroutine final_state(text)
    character(len=:), allocatable, intent(inout) :: text
    real(wp), allocatable :: final(:)
    integer, allocatable :: bodies(:)
    integer :: j
    character(len=16) :: name
    final = final_row(stats)
    if (allocated(input%bodies_out)) then
      bodies = input%bodies_out
    else
      bodies = [(j, j = 1, scene%n_bodies)]
    end if
    text = text // '  final     t =' // es(final(1))
    do j = 1, min(size(bodies), 10)
      write(name, '(i0)') bodies(j)
      text = text // '  x' // trim(name) // ' =' // es(final(2 * bodies(j))) // '  v' // trim(name) // ' =' // &
        es(final(2 * bodies(j) + 1))
    end do
    if (size(bodies) > 10) text = text // '  ...'
  end subroutine final_state

  !> What the summary says of the event log: its file and what it holds (&run events).
  function event_log_text() result(text)
    character(len=:), allocatable :: text
    if (stream .and. len(events_file) == 0 .and. scene%events /= events_none) then
      text = 'no event log (-o - writes the samples alone: --events-file FILE keeps one; ' // &
        trim(fmt(stats%n_events)) // ' events counted)'
      return
    end if
    select case (scene%events)
    case (events_none)
      text = 'no event log (events = ''none''; ' // trim(fmt(stats%n_events)) // ' events counted)'
    case (events_impacts)
      text = sink%event_path // ' (' // &
        trim(fmt(sum(stats%row_events(class_impact, :)))) // ' impacts of ' // &
        trim(fmt(stats%n_events)) // ' events: events = ''impacts'')'
    case default
      text = sink%event_path // ' (' // trim(fmt(stats%n_events)) // ' events)'
    end select
    if (sink%n_cut > 0) text = text(:len(text) - 1) // ', cut at ' // trim(fmt(sink%n_logged)) // &
      ': max_events)'
  end function event_log_text

  !> The summary's events line: each row's impacts, rests, releases, then each body's sticks
  !> and slips, then each friction contact's (&friction), by name; past max_named names (a
  !> long chain has thousands) each kind's total and on how many rows, bodies or contacts,
  !> which a line can hold (the event log has the rest).
  subroutine events_line(line)
    character(len=:), allocatable, intent(out) :: line
    integer, parameter :: max_named = 16
    character(len=*), parameter :: kinds(class_impact:class_pair_slip) = &
      [character(len=8) :: 'impacts', 'rests', 'releases', 'sticks', 'slips', 'sticks', 'slips']
    character(len=*), parameter :: counted_on(class_impact:class_pair_slip) = [character(len=9) :: &
      ' rows', ' rows', ' rows', ' bodies', ' bodies', ' contacts', ' contacts']
    integer :: c, k, named, total, on
    named = 0
    do c = class_impact, class_pair_slip
      do k = 1, entries(c)
        if (event_count(stats, c, first(c) + k) > 0) named = named + 1
      end do
    end do
    line = ''
    do c = class_impact, class_pair_slip
      total = 0
      on = 0
      do k = 1, entries(c)
        if (event_count(stats, c, first(c) + k) == 0) cycle
        if (named <= max_named) line = line // ' ' // trim(event_name(row_names(c), c, first(c) + k)) // ' ' // &
          trim(fmt(event_count(stats, c, first(c) + k)))
        total = total + event_count(stats, c, first(c) + k)
        on = on + 1
      end do
      if (named > max_named .and. on > 0) line = line // ' ' // trim(kinds(c)) // ' ' // trim(fmt(total)) // &
        ' on ' // trim(fmt(on)) // trim(counted_on(c))
    end do
    if (len(line) == 0) line = ' none'
  end subroutine events_line

  !> How many rows (impacts, rests, releases), bodies (sticks, slips) or friction contacts
  !> (theirs) an event class counts on.
  integer function entries(class)
    integer, intent(in) :: class
    entries = merge(scene%n_rows + scene%n_stops, scene%n_bodies, class < class_stick)
    if (class >= class_pair_stick) entries = scene%n_frictions
  end function entries

  !> The index before an event class's first (a friction contact's follow the rows).
  integer function first(class)
    integer, intent(in) :: class
    first = 0
    if (class >= class_pair_stick) first = scene%n_rows + scene%n_stops
  end function first

  !> The names an event class's events are named from (impact1d_output's event_name): the
  !> rows', and the friction contacts' after them.
  function row_names(class) result(names)
    integer, intent(in) :: class
    character(len=name_len), allocatable :: names(:)
    names = scene%row_name
    if (class >= class_pair_stick) names = [scene%row_name, scene%friction_name]
  end function row_names

  !> The summary on stdout. Every number in ES with a three-digit exponent (7.73913E+157
  !> lost its E in ES12.5).
  subroutine summary()
    character(len=:), allocatable :: text, line, where
    character(len=16) :: number
    real(wp), allocatable :: final(:)
    integer :: l
    ! The last full row (one, two or N bodies), the ledger after the bodies' x and v.
    final = final_row(stats)
    l = row_ledger(scene%n_bodies)
    text = 'impact1d: ' // trim(input%text(i_title)%s) // nl
    text = text // '  scene     ' // scene_path // ' (method ' // scene%method // ', dt = ' // &
      trim(fmt(scene%dt)) // ' s, t_end = ' // trim(fmt(scene%t_end)) // ' s)' // nl
    if (scene%substeps > 1) text = text // '  substeps  ' // trim(fmt(scene%substeps)) // &
      ' RK4 steps per dt given (substeps = ''auto'': the springs'' fastest mode at |lambda| dt <= ' // &
      '0.5)' // nl
    where = out_path
    if (stream) where = 'standard output'
    text = text // '  output    ' // where // ' (' // trim(fmt(scene%n_samples)) // ' rows every ' // &
      trim(fmt(scene%dt_out)) // ' s) and ' // trim(event_log_text()) // nl
    call events_line(line)
    text = text // '  events   ' // line // nl
    call final_state(text)
    text = text // nl // '  energy    KE =' // es(final(l + 1))
    if (scene%springs%has_spring) text = text // '  PE =' // es(final(l + 2))
    text = text // ' J' // nl // '  ledger    work =' // es(final(l + 3)) // '  friction loss =' // &
      es(final(l + 4)) // '  impact loss =' // es(final(l + 5))
    if (scene%springs%has_damper) text = text // '  damping loss =' // es(final(l + 6))
    if (scene%drives%n > 0 .or. scene%belts) text = text // '  drive work =' // es(final(l + 7))
    write(number, '(es10.2e3)') stats%max_residual
    text = text // '  |residual| <=' // trim(number) // ' J' // nl
    text = text // '  steps     ' // trim(fmt(stats%steps)) // ' RK4 steps' // nl
    ! Not an error, but the numbers need it said beside them (a step coarse for a spring).
    if (len(scene%warnings) > 0) text = text // '  warning   ' // scene%warnings // nl
    call sink%cut_note(line)
    if (len(line) > 0) text = text // '  warning   ' // line // nl
    if (stream) then
      call say(text, 'the summary', '(the samples went to standard output)')
    else
      call say(text, 'the summary', '(the output ' // out_path // ' is in place)')
    end if
  end subroutine summary

  !> Text to stdout (to stderr once the samples stream to stdout: -o -). Text that cannot
  !> be written (stdout closed, a full disk) is a failure, status 2, one line on stderr
  !> (ending with note, if given): after a run the output files are in place, but nobody
  !> saw how it went.
  subroutine say(text, what, note)
    character(len=*), intent(in) :: text, what
    character(len=*), intent(in), optional :: note
    character(len=:), allocatable :: reason
    call write_text(merge(2, 1, stream), text, reason)
    if (len(reason) == 0) return
    if (present(note)) reason = reason // ' ' // note
    call fail(status_simulation, 'cannot write ' // what // ' to ' // trim(merge('stderr', 'stdout', stream)) // &
      ': ' // reason)
  end subroutine say

  !> A number for the summary: ES with a three-digit exponent, which fits any double.
  function es(x) result(text)
    real(wp), intent(in) :: x
    character(len=13) :: text
    write(text, '(es13.5e3)') x
  end function es

  !> Command-line argument i, whatever its length.
  function argument_text(i) result(text)
    integer, intent(in) :: i
    character(len=:), allocatable :: text
    integer :: length
    call get_command_argument(i, length=length)
    allocate(character(len=length) :: text)
    if (length > 0) call get_command_argument(i, text)
  end function argument_text

  !> Option k of --t-end, --dt, --dt-out, --max-events takes the value just read.
  subroutine override(k)
    integer, intent(in) :: k
    overrides(k) = number(option, value)
    overridden(k) = .true.
  end subroutine override

  !> The whole text must be one number: a list-directed read alone would take '1e-3 junk'
  !> (or '2*0.1', a repeat count) and ignore the rest.
  real(wp) function number(name, text)
    character(len=*), intent(in) :: name, text
    integer :: ios
    ios = 1
    number = 0.0_wp
    if (len_trim(text) > 0) then
      if (scan(trim(adjustl(text)), ' ,;/*' // achar(9)) == 0) read(text, *, iostat=ios) number
    end if
    if (ios /= 0) call fail(status_input, name // ' ''' // text // ''': not a number')
  end function number

  !> The output replaces its target only when the run is done, so an output that is one of
  !> the run's inputs (the scene, a force table) would silently destroy it.
  subroutine refuse_to_overwrite_inputs(path)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: target, other
    call resolve(path, target)
    if (len(target) == 0) return
    call resolve(scene_path, other)
    if (target == other) call fail(status_input, 'cannot write output ' // path // &
      ': it is the scene file ' // scene_path // ' (choose another -o)')
    do k = i_f1_table, i_f2_table
      if (len_trim(input%text(k)%s) == 0) cycle
      call resolve(trim(input%text(k)%s), other)
      if (target == other) call fail(status_input, 'cannot write output ' // &
        path // ': it is the force table ' // trim(input%text(k)%s) // ' (choose another -o)')
    end do
  end subroutine refuse_to_overwrite_inputs


  !> Whether an output name means standard output: '-', or a name of file descriptor 1.
  logical function standard_output(path)
    character(len=*), intent(in) :: path
    standard_output = path == '-' .or. path == '/dev/stdout' .or. path == '/dev/fd/1' .or. &
      path == '/proc/self/fd/1'
  end function standard_output

  !> File name without folder and extension: input/case3.nml -> case3.
  function stem(path) result(name)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: name
    integer :: slash, dot
    slash = index(path, '/', back=.true.)
    name = path(slash + 1:)
    dot = index(name, '.', back=.true.)
    if (dot > 1) name = name(:dot - 1)
  end function stem

  subroutine fail(status, message)
    integer, intent(in) :: status
    character(len=*), intent(in) :: message
    write(error_unit, '(a)') 'impact1d: ' // message
    flush(error_unit)
    call c_exit(int(status, c_int))
  end subroutine fail
end program impact1d_cli
