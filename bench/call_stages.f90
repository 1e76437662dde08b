!> The Fortran share of a short run of case 3 (t_end = dt = dt_out = 1e-3), for
!> bench/call_profile.py, in three cumulative stages: prepare_scene (validation, build_scene),
!> then with the memory sink's reservation, then with `run` (one step, two samples). Best of 7
!> batches of 20000 each, printed as one JSON object (microseconds). Linked as core_run is
!> (bench/cvode_peer.py's build_core).
!> usage: call_stages SCENE
program call_stages
  use, intrinsic :: iso_fortran_env, only: dp => real64, int64
  use impact1d_error, only: error_type
  use impact1d_scene, only: scene_input, scene_type, i_dt, i_dt_out, i_t_end
  use impact1d_io, only: read_scene_file, prepare_scene
  use impact1d_output, only: memory_sink, present_columns
  use impact1d_solver, only: run, run_stats
  implicit none
  integer, parameter :: calls = 20000
  type(scene_input) :: input
  type(error_type), allocatable :: error
  character(len=4096) :: path
  integer :: i, b, stage
  integer(int64) :: c0, c1, rate
  real(dp) :: best(3)

  call get_command_argument(1, path)
  call read_scene_file(trim(path), input, error)
  if (allocated(error)) error stop 2
  input%value([i_dt, i_dt_out, i_t_end]) = 1e-3_dp
  call system_clock(count_rate=rate)
  best = huge(1.0_dp)
  do b = 1, 7
    do stage = 1, 3
      call system_clock(c0)
      do i = 1, calls
        call up_to(stage)
      end do
      call system_clock(c1)
      best(stage) = min(best(stage), real(c1 - c0, dp) / real(rate, dp) / calls)
    end do
  end do
  print '(a, f10.4, a, f10.4, a, f10.4, a)', '{"prepare_us": ', best(1) * 1e6, ', "reserve_us": ', best(2) * 1e6, &
    ', "run_us": ', best(3) * 1e6, '}'

contains

  !> A short run's Fortran work up to `stage` (1 prepare_scene, 2 + the sink, 3 + run).
  subroutine up_to(stage)
    integer, intent(in) :: stage
    type(scene_type) :: scene
    type(memory_sink) :: sink
    type(run_stats) :: stats
    call prepare_scene(input, scene, error)
    if (stage >= 2) call sink%reserve(scene%n_samples, present_columns(input))
    if (stage >= 3) call run(scene, sink, stats, error)
  end subroutine up_to
end program call_stages
