!> Prescribed motion of the ground end of a contact or element (docs/method.md section 11):
!> w(t) = v t + amp sin(omega t + phase), each term present only when named. The gap of a row
!> with a moving ground end is x_b - w(t) - limit, a spring to a moving anchor stretches by
!> x_b - w(t) - rest; w and its derivatives are evaluated exactly here (never interpolated),
!> so that the engine's gaps, impacts and held rows see the motion the user wrote.
module impact1d_drives
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: drive_type

  !> The scene's moving grounds, one per record that moves its ground end (nd of them).
  type :: drive_type
    integer :: n = 0                             !< nd (0: every ground stays still)
    real(wp), allocatable :: v(:)                !< (nd) constant velocity, m/s
    real(wp), allocatable :: amp(:), omega(:), phase(:)   !< (nd) the sine: m, rad/s (0: none), rad
    logical :: polynomial = .true.               !< no drive has a sine: w is linear in t
  contains
    procedure :: add
    procedure :: position
    procedure :: position_parts
    procedure :: rounded_part
    procedure :: displacement
    procedure :: displacement_parts
    procedure :: velocity
    procedure :: acceleration
    procedure :: jerk
  end type drive_type

contains

  !> One more drive (v, amp, omega, phase); its index is self%n after.
  pure subroutine add(self, v, amp, omega, phase)
    class(drive_type), intent(inout) :: self
    real(wp), intent(in) :: v, amp, omega, phase
    if (.not. allocated(self%v)) allocate(self%v(0), self%amp(0), self%omega(0), self%phase(0))
    self%v = [self%v, v]
    self%amp = [self%amp, amp]
    self%omega = [self%omega, omega]
    self%phase = [self%phase, phase]
    self%n = self%n + 1
    self%polynomial = self%polynomial .and. omega == 0.0_wp
  end subroutine add

  !> w_d(t).
  pure real(wp) function position(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = self%v(d) * t
    if (self%omega(d) /= 0.0_wp) w = w + self%amp(d) * sin(self%omega(d) * t + self%phase(d))
  end function position

  !> w_d at the clock t + t_lo as hi + lo: v t without rounding (Dekker's product), the
  !> clock's low part w' t_lo and the sine in lo. A body put on the ground (snapped) is then
  !> where the step, which moves a body held to it by the clock's exact increments, took it:
  !> with w rounded, each snap moved a held body by up to an ulp of its position, against
  !> the bodies in flight beside it, and a ground moving at constant speed did not give the
  !> still ground's rattle (two balls came to rest on a floor in 551 events, on the same
  !> floor seen from a moving frame in 346,946).
  pure subroutine position_parts(self, d, t, t_lo, hi, lo)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, t_lo
    real(wp), intent(out) :: hi, lo
    call exact_product(self%v(d), t, hi, lo)
    lo = lo + self%velocity(d, t) * t_lo
    if (self%omega(d) /= 0.0_wp) lo = lo + self%amp(d) * sin(self%omega(d) * t + self%phase(d))
  end subroutine position_parts

  !> a b = p + e exactly (Dekker's product: p rounded, e its error).
  pure subroutine exact_product(a, b, p, e)
    real(wp), intent(in) :: a, b
    real(wp), intent(out) :: p, e
    real(wp), parameter :: split = 134217729.0_wp   ! 2**27 + 1
    real(wp) :: c, a_hi, a_lo, b_hi, b_lo
    p = a * b
    c = split * a
    a_hi = c - (c - a)
    a_lo = a - a_hi
    c = split * b
    b_hi = c - (c - b)
    b_lo = b - b_hi
    e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo
  end subroutine exact_product

  !> The size of what position_parts rounds in w_d(t): the sine's |amp sin(omega t + phase)|
  !> (v t is exact there), for a gap's rounding level. Counting all of |w| made a floor
  !> moving at constant speed close gaps a still floor leaves open (2.5e-15 m at w = 0.7 m).
  pure real(wp) function rounded_part(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (self%omega(d) /= 0.0_wp) w = abs(self%amp(d) * sin(self%omega(d) * t + self%phase(d)))
  end function rounded_part

  !> w_d(t + h) - w_d(t), accurate however small h is against t (a difference of positions
  !> would round a step below the clock's ulp to 0): sin(a + c) - sin(a) = 2 cos(a + c/2)
  !> sin(c/2).
  pure real(wp) function displacement(self, d, t, h) result(dw)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, h
    dw = self%v(d) * h
    if (self%omega(d) /= 0.0_wp) dw = dw + 2.0_wp * self%amp(d) * cos(self%omega(d) * (t + 0.5_wp * h) + &
      self%phase(d)) * sin(0.5_wp * self%omega(d) * h)
  end function displacement

  !> displacement as hi + lo, its v h without rounding (exact_product): a body held to a
  !> ground moving at constant speed, moved by the clock's exact increments, stays on w(t)
  !> as position_parts forms it (with v h rounded it drifted off by 4e-18 m in 0.1 s, and a
  !> ball resting on a floor at 0.8 m/s was not closed on it when another ball landed).
  pure subroutine displacement_parts(self, d, t, h, hi, lo)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, h
    real(wp), intent(out) :: hi, lo
    hi = self%displacement(d, t, h)
    lo = 0.0_wp
    if (self%omega(d) == 0.0_wp) call exact_product(self%v(d), h, hi, lo)
  end subroutine displacement_parts

  !> w_d'(t).
  pure real(wp) function velocity(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = self%v(d)
    if (self%omega(d) /= 0.0_wp) w = w + self%amp(d) * self%omega(d) * cos(self%omega(d) * t + self%phase(d))
  end function velocity

  !> w_d''(t).
  pure real(wp) function acceleration(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (self%omega(d) /= 0.0_wp) w = -self%amp(d) * self%omega(d)**2 * sin(self%omega(d) * t + self%phase(d))
  end function acceleration

  !> w_d'''(t): which way the acceleration goes (a held row's force exactly at zero).
  pure real(wp) function jerk(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (self%omega(d) /= 0.0_wp) w = -self%amp(d) * self%omega(d)**3 * cos(self%omega(d) * t + self%phase(d))
  end function jerk
end module impact1d_drives
