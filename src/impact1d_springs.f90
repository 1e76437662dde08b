!> Linear springs and viscous dampers (docs/method.md, "Springs and dampers"): body 1 to the
!> ground, body 2 to the ground, and between the bodies along x2 - x1. Each element is
!> present only when the scene names it; a scene that names none has springs%present false
!> and the solver never calls this module.
module impact1d_springs
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: springs_type, n_elements

  !> Elements: 1 body 1 to the ground, 2 body 2 to the ground, 3 between the bodies.
  integer, parameter :: n_elements = 3

  type :: springs_type
    logical :: present = .false.                  !< any stiffness or damping named
    logical :: has_spring = .false., has_damper = .false.
    real(wp) :: k(n_elements) = 0.0_wp            !< stiffness, N/m
    real(wp) :: rest(n_elements) = 0.0_wp         !< x1_rest, x2_rest, d_rest
    real(wp) :: c(n_elements) = 0.0_wp            !< damping, N s/m
  contains
    procedure :: force
    procedure :: force_rate
    procedure :: potential
    procedure :: damping_power
    procedure :: frequency
    procedure :: linear_part
  end type springs_type

contains

  !> Elongations of the three springs for positions x + dx: dx carries the low parts of
  !> compensated positions (and a stage's displacement), added after the large terms cancel.
  pure function elongation(self, x, dx) result(e)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: x(2), dx(2)
    real(wp) :: e(n_elements)
    e(1) = (x(1) - self%rest(1)) + dx(1)
    e(2) = (x(2) - self%rest(2)) + dx(2)
    e(3) = ((x(2) - x(1)) - self%rest(3)) + (dx(2) - dx(1))
  end function elongation

  !> Rates of the three elongations.
  pure function elongation_rate(v) result(r)
    real(wp), intent(in) :: v(2)
    real(wp) :: r(n_elements)
    r = [v(1), v(2), v(2) - v(1)]
  end function elongation_rate

  !> Forces on both bodies at positions x + dx and velocities v.
  pure function force(self, x, dx, v) result(f)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: x(2), dx(2), v(2)
    real(wp) :: f(2), tension(n_elements)
    ! Tension of each element: what it pulls its ends together with.
    tension = self%k * elongation(self, x, dx) + self%c * elongation_rate(v)
    f(1) = -tension(1) + tension(3)
    f(2) = -tension(2) - tension(3)
  end function force

  !> Rate of the spring forces at velocities v (the dampers' part needs the accelerations
  !> and is left out: it only tells which way a force exactly at a bound goes next).
  pure function force_rate(self, v) result(df)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: v(2)
    real(wp) :: df(2), rate(n_elements)
    rate = self%k * elongation_rate(v)
    df(1) = -rate(1) + rate(3)
    df(2) = -rate(2) - rate(3)
  end function force_rate

  !> Potential energy stored in the springs.
  pure real(wp) function potential(self, x, dx)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: x(2), dx(2)
    potential = 0.5_wp * sum(self%k * elongation(self, x, dx)**2)
  end function potential

  !> Power the dampers dissipate at velocities v.
  pure real(wp) function damping_power(self, v)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: v(2)
    damping_power = sum(self%c * elongation_rate(v)**2)
  end function damping_power

  !> An upper bound of the fastest rate in the motion (rad/s): the stiffest natural
  !> frequency and the fastest damping rate over the lightest mass. Steps sample the
  !> mode's conditions at least 16 times per 2 pi of it.
  pure real(wp) function frequency(self, mass)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: mass(2)
    real(wp) :: stiffness, damping
    stiffness = self%k(1) + self%k(2) + 2.0_wp * self%k(3)
    damping = self%c(1) + self%c(2) + 2.0_wp * self%c(3)
    frequency = sqrt(stiffness / minval(mass)) + damping / minval(mass)
  end function frequency

  !> Stiffness and damping matrices (K, C in M x'' + C x' + K x = f) of n bodies (1 or 2:
  !> a one-body scene has no body-2 or link element).
  pure subroutine linear_part(self, n, k, c)
    class(springs_type), intent(in) :: self
    integer, intent(in) :: n
    real(wp), intent(out) :: k(n, n), c(n, n)
    call assemble(self%k, k)
    call assemble(self%c, c)
  end subroutine linear_part

  !> The matrix of the three elements' coefficients (to the ground, to the ground, between).
  pure subroutine assemble(coefficient, matrix)
    real(wp), intent(in) :: coefficient(n_elements)
    real(wp), intent(out) :: matrix(:, :)
    matrix = 0.0_wp
    matrix(1, 1) = coefficient(1)
    if (size(matrix, 1) == 1) return
    matrix(2, 2) = coefficient(2) + coefficient(3)
    matrix(1, 1) = matrix(1, 1) + coefficient(3)
    matrix(1, 2) = -coefficient(3)
    matrix(2, 1) = -coefficient(3)
  end subroutine assemble
end module impact1d_springs
