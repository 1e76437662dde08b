!> impact1d's core without Python (bench/cvode_peer.py): what `impact1d.simulate` runs in
!> Fortran for a scene read once, per run: build the checked scene (prepare_scene: validation,
!> derived data), a memory sink for its samples and events, `run`. Linked against the meson
!> build's core library (build/py/libimpact1d_core.a) with the release build's flags, so it
!> runs the code the Python package runs; it leaves out only the f2py layer and Python.
!> Times BATCHES batches of RUNS runs (the mean per run of each batch; the first run, and
!> reading the file, are not timed) and prints one JSON object: the best and the median
!> batch, the events and the final state of the last run.
!> usage: core_run SCENE DT DT_OUT BATCHES RUNS
program core_run
  use, intrinsic :: iso_fortran_env, only: dp => real64, int64, error_unit
  use impact1d_error, only: error_type
  use impact1d_scene, only: scene_input, scene_type, i_dt, i_dt_out
  use impact1d_io, only: read_scene_file, prepare_scene
  use impact1d_output, only: memory_sink, present_columns, event_name
  use impact1d_solver, only: run, run_stats
  implicit none
  type(scene_input) :: input
  type(error_type), allocatable :: error
  type(memory_sink) :: sink
  character(len=4096) :: path
  character(len=64) :: arg
  integer :: batches, runs, b, i
  integer(int64) :: c0, c1, rate
  real(dp) :: steps(2)
  real(dp), allocatable :: per_run(:)

  call get_command_argument(1, path)
  call read_scene_file(trim(path), input, error)
  if (allocated(error)) call fail(error%message)
  do i = 1, 2                                           ! dt, dt_out
    call get_command_argument(1 + i, arg)
    read(arg, *) steps(i)
  end do
  input%value([i_dt, i_dt_out]) = steps
  input%given([i_dt, i_dt_out]) = .true.
  call get_command_argument(4, arg)
  read(arg, *) batches
  call get_command_argument(5, arg)
  read(arg, *) runs
  allocate(per_run(batches))
  call one_run(sink)                                   ! warm-up: caches, first allocations
  call system_clock(count_rate=rate)
  do b = 1, batches
    call system_clock(c0)
    do i = 1, runs
      call one_run(sink)
    end do
    call system_clock(c1)
    per_run(b) = real(c1 - c0, dp) / real(rate, dp) / runs
  end do
  call report(sink, per_run)

contains

  !> One run as the flat API's simulate does it (without the f2py arrays).
  subroutine one_run(sink)
    type(memory_sink), intent(inout) :: sink
    type(scene_type) :: scene
    type(run_stats) :: stats
    type(error_type), allocatable :: error
    call prepare_scene(input, scene, error)
    if (allocated(error)) call fail(error%message)
    call sink%reserve(scene%n_samples, present_columns(input))
    call run(scene, sink, stats, error)
    if (allocated(error)) call fail(error%message)
  end subroutine one_run

  subroutine report(sink, per_run)
    type(memory_sink), intent(in) :: sink
    real(dp), intent(inout) :: per_run(:)
    integer :: j, k, n
    call sort(per_run)
    n = sink%n_samples
    write(*, '(a, es23.16, a, es23.16, a)') '{"best_s": ', per_run(1), ', "median_s": ', &
      per_run(size(per_run) / 2 + 1), ','
    ! Columns t x1 v1 x2 v2 first (a two-body scene).
    write(*, '(a, 4(es24.16e3, :, ", "))', advance='no') ' "final": [', (sink%samples(n, j), j = 2, 5)
    write(*, '(a)') '],'
    write(*, '(a)', advance='no') ' "events": ['
    do k = 1, sink%n_events
      write(*, '(a, es24.16e3, 3a)', advance='no') trim(merge('[  ', ', [', k == 1)), sink%event_time(k), &
        ', "', trim(event_name(sink%row_names, sink%event_class(k), sink%event_index(k))), '"]'
    end do
    write(*, '(a)') ']}'
  end subroutine report

  subroutine sort(x)
    real(dp), intent(inout) :: x(:)
    integer :: j, k
    real(dp) :: v
    do j = 2, size(x)
      v = x(j)
      k = j - 1
      do while (k >= 1)
        if (x(k) <= v) exit
        x(k + 1) = x(k)
        k = k - 1
      end do
      x(k + 1) = v
    end do
  end subroutine sort

  subroutine fail(message)
    character(len=*), intent(in) :: message
    write(error_unit, '(2a)') 'core_run: ', message
    error stop 2
  end subroutine fail
end program core_run
