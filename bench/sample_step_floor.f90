!> The floor of a summary run's sample-every-step work (bench/sweep_study.py): the steps a
!> run takes to its sample times under constant forces (each ends at the sample's time, its
!> sums compensated and renormalised, as impact1d's constant_step) and what a summary reads
!> of each sample (the kinetic energy, the energy residual and its largest value), in a
!> tight loop with nothing else: no events, no sink, no calls. Everything comes from the
!> command line so that nothing folds at compile time. Prints nanoseconds per step.
!> usage: sample_step_floor N_RUNS N_STEPS DT M1 M2 X1 V1 X2 V2
program sample_step_floor
  use, intrinsic :: iso_fortran_env, only: dp => real64, int64
  implicit none
  integer :: n_runs, n_steps, r, j
  integer(int64) :: c0, c1, rate
  real(dp) :: dt, m(2), x0(2), v0(2), a(2), t, t_lo, t_stop, h, x(2), x_lo(2), v(2), v_lo(2)
  real(dp) :: ke, ke0, residual, largest
  character(len=64) :: arg

  call get_command_argument(1, arg)
  read(arg, *) n_runs
  call get_command_argument(2, arg)
  read(arg, *) n_steps
  dt = argument(3)
  m = [argument(4), argument(5)]
  x0 = [argument(6), argument(8)]
  v0 = [argument(7), argument(9)]
  a = 0.0_dp
  largest = 0.0_dp
  call system_clock(c0, rate)
  do r = 1, n_runs
    t = 0.0_dp
    t_lo = 0.0_dp
    x = x0
    x_lo = 0.0_dp
    v = v0 * (1.0_dp + r * 1.0e-6_dp)
    v_lo = 0.0_dp
    ke0 = 0.5_dp * dot_product(m, v**2)
    do j = 1, n_steps
      t_stop = j * dt
      h = (t_stop - t) - t_lo
      call add_compensated(x, x_lo, h * ((v + v_lo) + (0.5_dp * h) * a))
      call add_compensated(v, v_lo, h * a)
      t = t_stop
      t_lo = 0.0_dp
      ke = 0.5_dp * dot_product(m, v**2)
      residual = ke - ke0
      if (.not. abs(residual) <= huge(1.0_dp)) error stop 'not finite'
      largest = max(largest, abs(residual))
    end do
  end do
  call system_clock(c1)
  print '(es12.4, 1x, es12.4)', 1.0e9_dp * real(c1 - c0, dp) / rate / (real(n_runs, dp) * n_steps), &
    largest + x(1)

contains

  real(dp) function argument(k)
    integer, intent(in) :: k
    character(len=64) :: text
    call get_command_argument(k, text)
    read(text, *) argument
  end function argument

  elemental subroutine add_compensated(hi, lo, increment)
    real(dp), intent(inout) :: hi, lo
    real(dp), intent(in) :: increment
    real(dp) :: total, rounded
    total = hi + increment
    rounded = total - hi
    lo = lo + ((hi - (total - rounded)) + (increment - rounded))
    hi = total
    total = hi + lo
    lo = lo - (total - hi)
    hi = total
  end subroutine add_compensated
end program sample_step_floor
