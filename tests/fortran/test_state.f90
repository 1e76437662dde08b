!> The compensated state: a clock advanced by 10^6 steps of 1e-5 s keeps its digits, and
!> the bulk constant-force steps of the glide give the bits of the step-by-step path.
program test_state
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_state, only: state_type, add_compensated, renormalise, constant_steps
  use impact1d_stepping, only: rk4_type
  use testing, only: check, finish
  implicit none
  integer, parameter :: n_steps = 1000000
  real(wp), parameter :: dt = 1.0e-5_wp
  ! A plain sum of 10^6 increments of 1e-5 drifts by ~1e-10: far outside this bound.
  real(wp), parameter :: naive_drift_floor = 1.0e-12_wp
  real(wp) :: t, t_lo, naive
  type(state_type) :: stepped, bulk
  type(rk4_type) :: rk
  real(wp) :: dv(2), half_dv(2)
  integer :: j

  t = 0.0_wp
  t_lo = 0.0_wp
  naive = 0.0_wp
  do j = 1, n_steps
    call add_compensated(t, t_lo, dt)
    naive = naive + dt
  end do
  ! The exact sum of 10^6 fl(1e-5) is within 1e-15 of 10: hi is it correctly rounded.
  call check(abs(t - 10.0_wp) <= spacing(10.0_wp), 'compensated clock: 10^6 steps of 1e-5 s give 10 s')
  call check(abs(naive - 10.0_wp) > naive_drift_floor, 'the plain sum does drift (the check can fail)')

  ! Bulk steps (accumulated, renormalised once) against step-by-step advance_constant.
  rk%constant_acceleration = [-9.81_wp, 0.37_wp]
  stepped%x = [0.3_wp, 10.0_wp]
  stepped%v = [1.7_wp, -0.2_wp]
  bulk = stepped
  do j = 1, 1000
    call rk%advance_constant(stepped, dt)
  end do
  dv = dt * rk%constant_acceleration
  half_dv = 0.5_wp * dv
  call constant_steps(1000_int64, dt, dv, half_dv, bulk%t, bulk%t_lo, bulk%x, bulk%x_lo, bulk%v, bulk%v_lo)
  call renormalise(bulk%t, bulk%t_lo)
  call renormalise(bulk%x, bulk%x_lo)
  call renormalise(bulk%v, bulk%v_lo)
  call check(bulk%t == stepped%t .and. bulk%t_lo == stepped%t_lo, 'bulk steps: same clock bits')
  call check(all(bulk%x == stepped%x) .and. all(bulk%v == stepped%v), &
    'bulk steps: same position and velocity bits as step by step')
  call finish('test_state')
end program test_state
