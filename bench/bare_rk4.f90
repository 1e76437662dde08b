!> The limit for the engine's stepping loop (bench/performance.py): a plain classical RK4
!> loop on the free-flight scenes' force law (no contacts, no friction),
!> y = (x1, v1, x2, v2), y' = (v1, f1(t)/m1, v2, f2/m2), with f1(t) = F1 + F1_AMP sin(2 pi t /
!> F1_PERIOD) when F1_AMP and F1_PERIOD are given, F1 otherwise, plus a spring to the ground
!> on body 1, -K1 (x1 - X1_REST), when those are given too (F1_AMP = 0: no sine). No events, no ledger, no
!> output but the final state. Everything comes from the command line so that nothing folds
!> at compile time; the bench compiles it with the release build's flags (-O3) and times it
!> the same way as the impact1d CLI (wall time of the process).
!> usage: bare_rk4 N_STEPS DT M1 M2 F1 F2 X1 V1 X2 V2 [F1_AMP F1_PERIOD [K1 X1_REST]]
program bare_rk4
  use, intrinsic :: iso_fortran_env, only: dp => real64, int64
  implicit none
  integer(int64) :: n, i
  real(dp) :: dt, m(2), f(2), y(4), t, k1(4), k2(4), k3(4), k4(4), amp, omega, stiffness, x_rest
  character(len=64) :: arg
  integer :: j

  call get_command_argument(1, arg)
  read(arg, *) n
  dt = argument(2)
  m = [argument(3), argument(4)]
  f = [argument(5), argument(6)]
  y = [(argument(6 + j), j = 1, 4)]
  amp = 0.0_dp
  omega = 0.0_dp
  if (command_argument_count() >= 12) then
    amp = argument(11)
    omega = 2.0_dp * acos(-1.0_dp) / argument(12)
  end if
  stiffness = 0.0_dp
  x_rest = 0.0_dp
  if (command_argument_count() >= 14) then
    stiffness = argument(13)
    x_rest = argument(14)
  end if
  t = 0.0_dp
  do i = 1, n
    k1 = rhs(t, y)
    k2 = rhs(t + 0.5_dp * dt, y + 0.5_dp * dt * k1)
    k3 = rhs(t + 0.5_dp * dt, y + 0.5_dp * dt * k2)
    k4 = rhs(t + dt, y + dt * k3)
    y = y + dt / 6.0_dp * (k1 + 2.0_dp * k2 + 2.0_dp * k3 + k4)
    t = t + dt
  end do
  print '(5es25.16)', t, y

contains

  !> Command-line argument i as a number.
  real(dp) function argument(i)
    integer, intent(in) :: i
    character(len=64) :: text
    call get_command_argument(i, text)
    read(text, *) argument
  end function argument

  pure function rhs(time, state) result(dydt)
    real(dp), intent(in) :: time, state(4)
    real(dp) :: dydt(4)
    if (stiffness /= 0.0_dp) then
      dydt = [state(2), (f(1) + amp * sin(omega * time) - stiffness * (state(1) - x_rest)) / m(1), &
        state(4), f(2) / m(2)]
    else if (amp == 0.0_dp) then
      dydt = [state(2), f(1) / m(1), state(4), f(2) / m(2)]
    else
      dydt = [state(2), (f(1) + amp * sin(omega * time)) / m(1), state(4), f(2) / m(2)]
    end if
    if (time < 0.0_dp) dydt = 0.0_dp   ! keeps the time argument of a general rhs
  end function rhs
end program bare_rk4
