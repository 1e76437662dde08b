!> The N-body output path the engine's results pass through: emit_bodies' full row (t, x1 v1
!> .. xN vN, ke, pe, work, friction_loss, impact_loss, damping_loss, residual) into a memory
!> sink and a file sink, with and without bodies_out, and the events of a scene of five
!> bodies (the pair a, b and its velocities) in both; one and two bodies in the tutorial's
!> row (t x1 v1 x2 v2, then the ledger; x2, v2 zero for one body).
program test_output
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type
  use impact1d_scene, only: scene_input
  use impact1d_output, only: memory_sink, file_sink, summary_sink, run_stats, emit_bodies, &
    present_columns, row_length, class_impact, class_stick, column_word, final_row
  use impact1d_fields, only: a_m
  use testing, only: check, finish
  implicit none
  integer, parameter :: n = 5
  real(wp), parameter :: x(n) = [0.0_wp, 1.0_wp, 2.5_wp, 4.0_wp, 7.0_wp], v(n) = [1.0_wp, -2.0_wp, 0.5_wp, 0.0_wp, 3.0_wp], &
    mass(n) = [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp]
  real(wp), parameter :: ke = 0.5_wp * (1.0_wp + 8.0_wp + 0.75_wp + 0.0_wp + 45.0_wp)
  type(scene_input) :: input
  character(len=*), parameter :: path = 'build/test_output_nbody.dat'

  input%chain%n_bodies = n
  input%chain%array(a_m)%n = n
  input%chain%array(a_m)%v = mass
  call memory_rows()
  input%bodies_out = [2, 5]
  call memory_rows()
  call file_rows()
  deallocate(input%bodies_out)
  call file_rows()
  call tutorial_rows()
  call summary_of_five_bodies()
  call finish('test_output')

contains

  !> The memory sink keeps the columns present_columns gives: every body's x and v, or
  !> bodies_out's, and the ledger over every body; events with their pair.
  subroutine memory_rows()
    type(memory_sink) :: sink
    type(run_stats) :: stats
    type(error_type), allocatable :: error
    integer, allocatable :: columns(:)
    real(wp), allocatable :: expected(:)
    columns = present_columns(input)
    call sink%reserve(2, columns)
    call emit_bodies(sink, stats, 0.5_wp, x, v, mass, 1.0_wp, 2.0_wp, 0.25_wp, 0.125_wp, .false., &
      [0.0_wp, 0.0_wp, 0.0_wp], error)
    call check(.not. allocated(error), 'emit_bodies: no error')
    call check(size(stats%row) == row_length(n) .and. row_length(n) == 2 * n + 9, 'the full row is 2 N + 9 long')
    if (allocated(input%bodies_out)) then
      expected = [0.5_wp, x(2), v(2), x(5), v(5)]
    else
      expected = [0.5_wp, 0.0_wp, 1.0_wp, 1.0_wp, -2.0_wp, 2.5_wp, 0.5_wp, 4.0_wp, 0.0_wp, 7.0_wp, 3.0_wp]
    end if
    ! ke, work, friction_loss, impact_loss, residual = ke - ke0 - work + losses
    expected = [expected, ke, 2.0_wp, 0.25_wp, 0.125_wp, ke - 1.0_wp - 2.0_wp + 0.25_wp + 0.125_wp]
    call check(sink%n_samples == 1 .and. size(sink%samples, 2) == size(expected), 'one row of the columns written')
    if (size(sink%samples, 2) == size(expected)) call check(all(sink%samples(1, :) == expected), &
      'the row: t, the bodies'' x and v, ke over every body, the ledger, the residual')
    call check(stats%max_residual == abs(expected(size(expected))), 'max_residual is the residual''s size')
    call check(column_word(columns(4), n) == merge('x5', 'x2', allocated(input%bodies_out)) .and. &
      column_word(row_length(n), n) == 'residual', 'the columns'' names')
    sink%row_names = [character(len=32) :: 'stop3', 'link_2_5']
    call sink%put_event(1.5_wp, class_impact, 2, 2, 5, [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp])
    call sink%put_event(2.0_wp, class_stick, 4, 4, 0, [0.5_wp, 0.0_wp, 0.0_wp, 0.0_wp])
    call check(sink%n_events == 2, 'two events kept')
    if (sink%n_events == 2) call check(all(sink%event_ends(:, 1) == [2, 5]) .and. all(sink%event_ends(:, 2) == [4, 0]) &
      .and. all(sink%event_v(:, 1) == [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp]), 'events keep their pair and velocities')
  end subroutine memory_rows

  !> The file sink writes the header (bodies = 5, the columns' names: no pe, damping_loss for
  !> a scene that names no spring) and its rows, and an
  !> events file of lines 't kind a b va_before vb_before va_after vb_after'.
  subroutine file_rows()
    type(file_sink) :: sink
    type(run_stats) :: stats
    type(error_type), allocatable :: error
    character(len=1024) :: line, last_comment, kind
    character(len=:), allocatable :: names
    integer :: unit, ios, a, b, n_rows, n_lines, n_masses
    real(wp) :: values(2 * n + 8), t, ev(4)
    call sink%open(path, input, error)
    call check(.not. allocated(error), 'the file sink opens')
    if (allocated(error)) return
    sink%row_names = [character(len=32) :: 'stop3', 'link_2_5']
    call emit_bodies(sink, stats, 0.5_wp, x, v, mass, 1.0_wp, 2.0_wp, 0.25_wp, 0.125_wp, .true., &
      [3.0_wp, 1.0_wp, 0.5_wp], error)
    call sink%put_event(1.5_wp, class_impact, 2, 2, 5, [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp])
    call sink%put_event(2.0_wp, class_stick, 4, 4, 0, [0.5_wp, 0.0_wp, 0.0_wp, 0.0_wp])
    call sink%close(.true., error)
    call check(.not. allocated(error), 'the file sink closes, its files in place')
    if (allocated(error)) return
    if (allocated(input%bodies_out)) then
      names = 't x2 v2 x5 v5 ke work friction_loss impact_loss residual'
    else
      names = 't x1 v1 x2 v2 x3 v3 x4 v4 x5 v5 ke work friction_loss impact_loss residual'
    end if
    open(newunit=unit, file=path, status='old', action='read')
    n_rows = 0
    n_lines = 0
    n_masses = 0
    do
      read(unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      n_lines = n_lines + 1
      if (line(1:1) == '#') then
        last_comment = line
        if (line == '# bodies = 5') n_lines = -1000
        if (line == '# m = 1.0 2.0 3.0 4.0 5.0') n_masses = n_masses + 1
        cycle
      end if
      n_rows = n_rows + 1
      read(line, *) values(:count_words(names))
    end do
    close(unit)
    call check(n_lines < 0, 'the header says bodies = 5')
    call check(n_masses == 1, 'the header has the masses as written: # m = 1.0 2.0 3.0 4.0 5.0')
    call check(trim(last_comment) == '# ' // names, 'the last header line names the columns: ' // trim(last_comment))
    call check(n_rows == 1, 'one row written')
    if (allocated(input%bodies_out)) then
      call check(all(values(:5) == [0.5_wp, 1.0_wp, -2.0_wp, 7.0_wp, 3.0_wp]), 'the row has bodies 2 and 5')
      ! (the scene names no spring: no pe, damping_loss columns; the residual counts what the
      ! engine passed: ke + pe - (ke0 + pe0) - work + losses + damping)
      call check(values(6) == ke .and. values(7) == 2.0_wp .and. &
        values(10) == ((ke + 3.0_wp) - (1.0_wp + 1.0_wp)) - 2.0_wp + 0.25_wp + 0.125_wp + 0.5_wp, &
        'ke over every body, the ledger, the residual with springs')
    end if
    open(newunit=unit, file='build/test_output_nbody.events.dat', status='old', action='read')
    read(unit, '(a)') line
    read(unit, '(a)') line
    call check(trim(line) == '# t kind a b va_before vb_before va_after vb_after', 'the events header')
    read(unit, *) t, kind, a, b, ev
    call check(t == 1.5_wp .and. kind == 'link_2_5' .and. a == 2 .and. b == 5 .and. &
      all(ev == [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp]), 'an impact line: its row''s name, its ends, their velocities')
    read(unit, *) t, kind, a, b, ev
    call check(t == 2.0_wp .and. kind == 'stick4' .and. a == 4 .and. b == 0 .and. ev(1) == 0.5_wp, &
      'a stick line: the body, 0')
    close(unit, status='delete')
    open(newunit=unit, file=path, status='old')
    close(unit, status='delete')
  end subroutine file_rows

  integer function count_words(text)
    character(len=*), intent(in) :: text
    integer :: k
    count_words = 1
    do k = 1, len(text)
      if (text(k:k) == ' ') count_words = count_words + 1
    end do
  end function count_words

  !> One and two bodies: the tutorial's 13 columns, x2 and v2 zero for one body, the ledger
  !> after them (ke, pe, work, friction_loss, impact_loss, damping_loss, drive_work, residual).
  subroutine tutorial_rows()
    type(memory_sink) :: sink
    type(run_stats) :: stats
    type(error_type), allocatable :: error
    real(wp), parameter :: x2(2) = [0.1_wp, 0.7_wp], v2(2) = [0.3_wp, -1.1_wp], m2(2) = [1.3_wp, 0.9_wp]
    real(wp) :: ke2
    integer :: k
    call sink%reserve(2, [(k, k = 1, 13)])
    ke2 = 0.5_wp * (m2(1) * v2(1)**2 + m2(2) * v2(2)**2)
    call emit_bodies(sink, stats, 0.3_wp, x2, v2, m2, 0.2_wp, 0.1_wp, 0.01_wp, 0.02_wp, .true., &
      [0.4_wp, 0.3_wp, 0.05_wp], error)
    call check(size(stats%row) == 13 .and. all(stats%row(1:5) == [0.3_wp, x2(1), v2(1), x2(2), v2(2)]) .and. &
      abs(stats%row(6) - ke2) <= 4.0_wp * epsilon(1.0_wp) * ke2 .and. all(stats%row(7:12) == [0.4_wp, 0.1_wp, &
      0.01_wp, 0.02_wp, 0.05_wp, 0.0_wp]), 'two bodies: t x1 v1 x2 v2, then the ledger')
    call emit_bodies(sink, stats, 0.4_wp, x2(:1), v2(:1), m2(:1), 0.2_wp, 0.1_wp, 0.01_wp, 0.02_wp, .false., &
      [0.0_wp, 0.0_wp, 0.0_wp], error)
    call check(size(stats%row) == 13 .and. all(stats%row(1:5) == [0.4_wp, x2(1), v2(1), 0.0_wp, 0.0_wp]), &
      'one body: x2 and v2 zero in the same 13 columns')
    call check(sink%n_samples == 2 .and. all(sink%samples(2, 1:5) == stats%row(1:5)), 'both rows in the sink')
  end subroutine tutorial_rows

  !> A sweep's summary of five bodies: at rest only when every body is (v1 = v2 = 0 with v4
  !> moving is not rest), from the samples (an event reports its pair only).
  subroutine summary_of_five_bodies()
    type(summary_sink) :: sink
    type(run_stats) :: stats
    type(error_type), allocatable :: error
    real(wp) :: moving(n), still(n)
    real(wp), allocatable :: row(:)
    moving = 0.0_wp
    moving(4) = 1.0_wp
    still = 0.0_wp
    sink = summary_sink(n_bodies=n)
    call emit_bodies(sink, stats, 1.0_wp, x, moving, mass, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, .false., &
      [0.0_wp, 0.0_wp, 0.0_wp], error)
    ! (an impact leaving its pair at rest while body 4 moves: not the rest of the run)
    call sink%put_event(1.5_wp, class_impact, 1, 1, 2, [1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp])
    call check(ieee_is_nan(sink%rest_time(final_row(stats))), 'body 4 moves at the end: no rest time')
    call emit_bodies(sink, stats, 2.0_wp, x, still, mass, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, .false., &
      [0.0_wp, 0.0_wp, 0.0_wp], error)
    call check(sink%rest_time(final_row(stats)) == 2.0_wp, 'every body at rest from the sample at t = 2')
    row = final_row(stats)
    call check(size(row) == row_length(n) .and. row(1) == 2.0_wp, 'final_row is the N-body row')
  end subroutine summary_of_five_bodies

end program test_output
