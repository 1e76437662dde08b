!> The &sine records in forcing_type: each body's terms in record order after its own sine
!> (set_sines groups records given in any order by body), their rate, and what they make of
!> varies, is_polynomial and fastest.
program test_forcing
  use impact1d_kinds, only: wp
  use impact1d_forcing, only: forcing_type, angular_frequency
  use testing, only: check, finish
  implicit none
  type(forcing_type) :: forcing
  ! (volatile: the compiler must not fold the expected sums' sines at compile time, where
  ! they are rounded otherwise than the library's at run time)
  real(wp), volatile :: t = 0.37_wp
  ! Records in file order: body 2, body 1, body 2 (body 2's sum: record 1, then record 3).
  integer, parameter :: body(3) = [2, 1, 2]
  real(wp), parameter :: amp(3) = [1.5_wp, -0.25_wp, 3.0_wp], period(3) = [0.7_wp, 1.9_wp, 0.2_wp], &
    phase(3) = [0.0_wp, 0.4_wp, -1.1_wp]
  real(wp) :: f(2), df(2), want(2), want_rate(2), w(3)
  integer :: j

  call forcing%allocate_bodies(2)
  forcing%constant = [0.5_wp, -0.125_wp]
  call forcing%set_varies()
  call check(.not. forcing%varies .and. forcing%is_polynomial() .and. forcing%fastest == 0.0_wp, &
    'no sine: constant, polynomial, no fastest sine')
  ! Body 1's own sine, then the records.
  forcing%has_sine(1) = .true.
  forcing%amp(1) = 0.75_wp
  forcing%omega(1) = angular_frequency(2.5_wp)
  forcing%phase(1) = 0.3_wp
  call forcing%set_sines(body, amp, period, phase)
  call forcing%set_varies()
  call check(forcing%varies .and. .not. forcing%is_polynomial(), '&sine records: varying, not polynomial')
  call check(all(forcing%sine_start == [1, 2, 4]), 'the records grouped by body')
  w = angular_frequency(period)
  call check(forcing%fastest == w(3), 'fastest: the largest omega of all the sines')

  ! The sums in the documented order: constant, own sine, records in record order.
  want(1) = forcing%constant(1) + forcing%amp(1) * sin(forcing%omega(1) * t + forcing%phase(1))
  want(1) = want(1) + amp(2) * sin(w(2) * t + phase(2))
  want(2) = forcing%constant(2) + amp(1) * sin(w(1) * t + phase(1))
  want(2) = want(2) + amp(3) * sin(w(3) * t + phase(3))
  call forcing%force_all(t, f)
  call check(all(f == want), 'force_all: each body its own sine, then its records in record order')

  ! The rate: d/dt of each term, against a central difference of the force.
  want_rate(1) = forcing%amp(1) * forcing%omega(1) * cos(forcing%omega(1) * t + forcing%phase(1)) + &
    amp(2) * w(2) * cos(w(2) * t + phase(2))
  want_rate(2) = amp(1) * w(1) * cos(w(1) * t + phase(1)) + amp(3) * w(3) * cos(w(3) * t + phase(3))
  call forcing%rate(t, df)
  call check(all(abs(df - want_rate) <= 1.0e-14_wp * maxval(abs(want_rate))), 'rate: the sum of the terms'' rates')
  call check(all(abs(df - difference(forcing, t)) <= 1.0e-6_wp * maxval(abs(want_rate))), &
    'rate: the derivative of force_all (central difference)')
  do j = 1, 3
    call check(abs(df(body(j))) > 0.0_wp, 'rate: every body with a record varies')
  end do
  call finish('test_forcing')

contains

  !> (f(t + h) - f(t - h)) / 2h.
  function difference(forcing, t) result(d)
    type(forcing_type), intent(in) :: forcing
    real(wp), intent(in) :: t
    real(wp) :: d(2), fp(2), fm(2)
    real(wp), parameter :: h = 1.0e-5_wp
    call forcing%force_all(t + h, fp)
    call forcing%force_all(t - h, fm)
    d = (fp - fm) / (2.0_wp * h)
  end function difference
end program test_forcing
